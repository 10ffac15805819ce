"""Where the flank kernel's CPU goes inside it (issue 33 item 4), on a recorded replay of the unscaled seat motor at
its defaults (scenarios/seat_motor.yaml, contact3d, exact flanks, `contact.flank_contacts: 4`, 32 slices, medium,
its 6.4 us step): the kernel's inputs of --steps consecutive steps from --warm-s (worm and wheel angle, the window
teeth) and the kernel's whole state at the first of them (memo included), replayed by one compiled loop over
`find_packed`, the variants interleaved over --rounds rounds (thread CPU; the median per variant).

numba has no profiler, so each part's cost is measured as what doing it twice adds: a variant of
wormsim/tooth/kernel.py (its text rewritten, loaded as a module of its own) evaluates the part a second time on an
input that is equal to the first's but not provably so to the compiler (x + 0.0 * tmp[0]), and throws the second
result away (y + 0.0 * y2): the contacts stay bit-identical (checked against the plain kernel's per step), the
control flow is the same, only the part's cost doubles. The parts: the gap's evaluation (worm_gap_ext inside _g),
the start point (_start_point), the line share (_line_share), the contact's write (_write_contact, the line share
included), the memo's check (_memo_skips), and after find_contacts the slice weights, the merge and the merged
contacts' frames.
A counting variant counts per call: slices in the candidate window, skipped by the memo, evaluated, gap evaluations,
the descent's walk beyond its first three points, contacts, _excess evaluations.

--base COMMIT: the kernel.py of that commit (with that commit's worm gap, wormsim/tooth/gap.py, where it differs
from this one's) is the one whose parts are measured (default: this one); with --other
FILE (another version of kernel.py, e.g. this one) that one is replayed too, interleaved with the base, and their
contacts compared per step (--only none: no part doubled).

    .venv/bin/python studies/kernel_replay.py [--warm-s 0.05] [--steps 3000] [--rounds 5] [--base COMMIT]
        [--other FILE] [--only PART,...] [--record kernel_replay]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
KERNEL = ROOT / "wormsim" / "tooth" / "kernel.py"
SPEED = ["contact.geometry=flanks", "simulation.mass_scaling=1", "simulation.record_every=156"]
VARIANT_DIR = Path("/tmp/wormsim_kernel_variants")
COUNTERS = ("candidate slices", "memo skips", "evaluated slices", "gap evaluations", "descent walk points")
COUNTERS += ("contacts", "_excess evaluations", "_line_share calls")
GAP_IMPORT = "from wormsim.tooth.gap import worm_gap_ext, wrap\n"  # kernel.py's; a base's gap.py replaces it
C0 = 6  # the counting variant's counters in tmp[C0:], its tmp enlarged

# each variant: (source line or fragment, its replacement); the part is done twice, its second result discarded
DOUBLE = {
    "gap evaluation (worm_gap_ext)": [
        (
            "    gv, ex = worm_gap_ext(xs, ys, zs, theta1, P, tmp)\n",
            "    gv, ex = worm_gap_ext(xs, ys, zs, theta1, P, tmp)\n"
            "    gv2, ex2 = worm_gap_ext(xs + 0.0 * tmp[0], ys, zs, theta1, P, tmp)\n"
            "    gv, ex = gv + 0.0 * gv2, ex + 0.0 * ex2\n",
        )
    ],
    "_start_point (bisection)": [
        (
            "                i_s = _start_point(c, span, sg, j, target)\n",
            "                i_s = _start_point(c, span, sg, j, target)\n"
            "                i_s = min(i_s, _start_point(c, span, sg, j, target + 0.0 * tmp[0]))\n",
        )
    ],
    "_line_share": [
        (
            "    w, tip = _line_share(xy, sc, zeta, sg, j, ib, ca, sa, P, tmp)\n",
            "    w, tip = _line_share(xy, sc, zeta, sg, j, ib, ca, sa, P, tmp)\n"
            "    w2, tip2 = _line_share(xy, sc, zeta, sg, j, ib, ca + 0.0 * tmp[0], sa, P, tmp)\n"
            "    w = w + 0.0 * w2 + 0.0 * tip2[0]\n",
        )
    ],
    "_write_contact (line share included)": [
        (
            "    _write_contact(ev, sc, zeta, slc, (ib, x), (gmin, gline, taper, (best, qa, qb, ib)), out, n)\n",
            "    _write_contact(ev, sc, zeta, slc, (ib, x + 0.0 * ev[5][0]), (gmin, gline, taper, (best, qa, qb, ib)), "
            "out, n)\n"
            "    _write_contact(ev, sc, zeta, slc, (ib, x), (gmin, gline, taper, (best, qa, qb, ib)), out, n)\n",
        )
    ],
    "_memo_skips": [
        (
            "                if use_memo and _memo_skips(mtab, mc, k, sg, j, theta1, te, drift, rate):\n",
            "                skip2 = use_memo and _memo_skips(mtab, mc, k, sg, j, theta1 + 0.0 * tmp[0], te, drift, "
            "rate)\n"
            "                if use_memo and (_memo_skips(mtab, mc, k, sg, j, theta1, te, drift, rate) or skip2):\n",
        )
    ],
    "slice_weights + merge + frames": [
        (
            "    n = slice_weights(meta, line, n, S, pos, nrm, depth, weight)\n",
            "    n0 = n\n"
            "    n = slice_weights(meta, line, n0, S, pos, nrm, depth, weight)\n"
            "    n = slice_weights(meta, line, n0, S, pos, nrm, depth, weight)\n",
        ),
        (
            "        nm = merge_flanks(meta, n, (pos, nrm, depth, weight), grp, share, merged, axes, ib[6])\n",
            "        nm = merge_flanks(meta, n, (pos, nrm, depth, weight), grp, share, merged, axes, ib[6])\n"
            "        nm = merge_flanks(meta, n, (pos, nrm, depth, weight), grp, share, merged, axes, ib[6])\n",
        ),
        (
            "        contact_frames(mnrm, nm, mframe)\n",
            "        contact_frames(mnrm, nm, mframe)\n        contact_frames(mnrm, nm, mframe)\n",
        ),
    ],
}

COUNT = [
    ("(MEMO_CONSTS,), (6,), (N,)", f"(MEMO_CONSTS,), ({C0 + len(COUNTERS)},), (N,)"),
    (
        "                if hi < c_range[sg, j, 0] or lo > c_range[sg, j, 1]:\n                    continue\n",
        "                if hi < c_range[sg, j, 0] or lo > c_range[sg, j, 1]:\n                    continue\n"
        f"                tmp[{C0}] += 1.0\n",
    ),
    (
        "                if use_memo and _memo_skips(mtab, mc, k, sg, j, theta1, te, drift, rate):\n",
        "                if use_memo and _memo_skips(mtab, mc, k, sg, j, theta1, te, drift, rate):\n"
        f"                    tmp[{C0 + 1}] += 1.0\n",
    ),
    ("                sid += 1\n", f"                sid += 1\n                tmp[{C0 + 2}] += 1.0\n"),
    ("    stamp[i] = sid\n", f"    stamp[i] = sid\n    tmp[{C0 + 3}] += 1.0\n"),
    ("\n        elif gn < best:\n", f"\n        elif gn < best:\n            ev[5][{C0 + 4}] += 1.0\n"),
    ("    return n + 1, False\n", f"    ev[5][{C0 + 5}] += 1.0\n    return n + 1, False\n"),
    (
        'no angle (the face slope needs no gap)."""\n',
        f'no angle (the face slope needs no gap)."""\n    tmp[{C0 + 6}] += 1.0\n',
    ),
    ("    S = zeta.shape[0]\n    dz = ", f"    S = zeta.shape[0]\n    tmp[{C0 + 7}] += 1.0\n    dz = "),
]


def _rewrite(src: str, subs) -> str:
    for a, b in subs:
        if src.count(a) != 1:
            raise SystemExit(f"kernel_replay: the variant's anchor is not unique in kernel.py: {a!r}")
        src = src.replace(a, b)
    return src


def load_module(name: str, src: str):
    """kernel.py's text `src` as a module of its own (its own numba cache next to it)."""
    VARIANT_DIR.mkdir(exist_ok=True)
    src = src.replace("cache=True", "cache=False")  # numba's cache cannot reload a module loaded from a path
    f = VARIANT_DIR / f"{name}.py"
    if not f.exists() or f.read_text() != src:
        f.write_text(src)
    spec = importlib.util.spec_from_file_location(f"kernel_variant_{name}", f)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def record(warm_s: float, steps: int):
    """The seat motor from rest to warm_s (the Python split step, FlankContacts.add), then the kernel's inputs of
    `steps` steps (theta1, theta2, the window teeth) and its buffers before the first of them."""
    import mujoco

    from wormsim.contact3d import native
    from wormsim.contact3d.flank_step import FlankContacts
    from wormsim.contact3d.mjcf import build_model
    from wormsim.scenario import load_scenario

    bm = build_model(load_scenario(ROOT / "scenarios" / "seat_motor.yaml", SPEED))
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    native.split_forward(m, d, fc.add)
    fc.set_friction(0.05)
    dt = m.opt.timestep
    nw = int(round(warm_s / dt))
    t = (np.arange(nw + steps) + 0.5) * dt
    cmd, load = bm.plan.commands.drive(t), bm.plan.commands.load(t)
    rec = {"t1": [], "t2": [], "ks": []}
    state: dict = {}
    add = fc.add

    def hook(m, d):
        if state.get("on"):
            if "fb" not in state:
                state["fb"], state["ib"] = fc.kernel.fb.copy(), fc.kernel.ib.copy()
            q = d.qpos
            fc.window(q[fc.qa2])
            rec["t1"].append(float(q[fc.qa1]))
            rec["t2"].append(float(q[fc.qa2]))
            rec["ks"].append(fc.ks.copy())
        add(m, d)

    for j in range(nw + steps):
        state["on"] = j >= nw
        d.ctrl[bm.drive_actuator], d.ctrl[bm.load_actuator] = cmd[j], load[j]
        native.split_step(m, d, hook)
    return {
        "fc": fc,
        "fb": state["fb"],
        "ib": state["ib"],
        "t1": np.array(rec["t1"]),
        "t2": np.array(rec["t2"]),
        "ks": np.array(rec["ks"]),
        "margin": fc.margin0,
        "taper": fc.taper_rad,
        "dt": dt,
    }


def _driver(fp):
    import numba

    @numba.njit
    def drive(fb, ib, ks, KS, T1, T2, margin, taper, out_n, out_nm):
        for i in range(T1.shape[0]):
            ks[:] = KS[i]
            out_n[i] = fp(fb, ib, T1[i], T2[i], margin, taper)
            out_nm[i] = ib[7]

    return drive


class Replay:
    """One kernel module's replay of `rec`: its PackedKernel at the recorded state, the compiled driver."""

    def __init__(self, mod, rec):
        fc = rec["fc"]
        self.mod = mod
        k = mod.PackedKernel(fc.grid, fc.params, len(fc.depth), len(fc.ks), fc.bm.geometry.z2, fc.group)
        # the recorded state, field by field (a variant's layout may differ)
        fields = {}
        from wormsim.tooth import kernel as base

        fs, is_ = base._layout(*(int(x) for x in rec["ib"][:6]))
        views = base._cut(rec["fb"], 0, fs) + base._cut(rec["ib"], base._I_HEADER, is_)
        for name, v in zip(base._F_FIELDS + base._I_FIELDS, views, strict=True):
            fields[name] = v
        self.k, self.fields = k, fields
        self.drive = _driver(mod.find_packed)
        T = len(rec["t1"])
        self.n, self.nm = np.zeros(T, dtype=np.int64), np.zeros(T, dtype=np.int64)
        self.rec = rec
        self.outs: dict = {}

    def reset(self) -> None:
        k = self.k
        for name, v in self.fields.items():
            dst = getattr(k, name, None)
            if dst is None:  # a field this version has not got
                continue
            # a field of another size in this version (the counting variant's tmp, another version's memo columns):
            # the common part, the rest zero
            dst[...] = 0.0
            common = tuple(slice(0, min(x, y)) for x, y in zip(dst.shape, v.shape, strict=True))
            dst[common] = v[common]
        k.ib[6:8] = self.rec["ib"][6:8]

    def run(self) -> float:
        """CPU seconds (this thread) of one replay from the recorded state."""
        self.reset()
        r = self.rec
        c0 = time.thread_time()
        self.drive(self.k.fb, self.k.ib, self.k.ks, r["ks"], r["t1"], r["t2"], r["margin"], r["taper"], self.n, self.nm)
        return time.thread_time() - c0

    def last(self) -> np.ndarray:
        """The last step's merged contacts (pos, normal, depth, weight) as one array."""
        k, nm = self.k, int(self.k.ib[7])
        return np.concatenate([k.mpos[:nm].ravel(), k.mnrm[:nm].ravel(), k.mdepth[:nm], k.mweight[:nm]])


def same_contacts(a: Replay, b: Replay) -> dict:
    """Per step: contacts and merged contacts equal; the last step's merged contacts' largest difference."""
    x, y = a.last(), b.last()
    return {
        "contacts_equal": bool(np.array_equal(a.n, b.n) and np.array_equal(a.nm, b.nm)),
        "last_step_max_abs_diff": float(np.max(np.abs(x - y))) if x.shape == y.shape else float("inf"),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warm-s", type=float, default=0.05)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--base", default="", help="commit whose kernel.py's parts are measured (default: this one)")
    ap.add_argument("--other", default="", help="another kernel.py (a file) replayed against the base")
    ap.add_argument(
        "--only",
        default="",
        help="comma-separated part names to double, count: the counts (default: all; none: no part)",
    )
    ap.add_argument("--record", default="")
    a = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from wormsim.results.provenance import provenance
    from wormsim.results.provenance import record as write_record

    load0 = os.getloadavg()
    if a.base:
        git = ["git", "-C", str(ROOT), "show", f"{a.base}:wormsim/tooth/kernel.py"]
        src = subprocess.run(git, check=True, capture_output=True, text=True).stdout
        git[-1] = f"{a.base}:wormsim/tooth/gap.py"
        gap_src = subprocess.run(git, check=True, capture_output=True, text=True).stdout
        if gap_src != (ROOT / "wormsim" / "tooth" / "gap.py").read_text():  # the base's worm gap too
            sys.modules["kernel_variant_gap_base"] = load_module("gap_base", gap_src)
            src = _rewrite(src, [(GAP_IMPORT, GAP_IMPORT.replace("wormsim.tooth.gap", "kernel_variant_gap_base"))])
    else:
        src = KERNEL.read_text()
    mods = {"plain": load_module("plain", src)}
    if a.other:
        mods["other"] = load_module("other", Path(a.other).read_text())
    for i, (name, subs) in enumerate(DOUBLE.items()):
        if not a.only or name in a.only.split(","):
            mods[f"x2 {name}"] = load_module(f"double{i}", _rewrite(src, subs))
    counting = not a.only or "count" in a.only.split(",")
    if counting:
        mods["count"] = load_module("count", _rewrite(src, COUNT))
    rec = record(a.warm_s, a.steps)
    print(f"recorded {len(rec['t1'])} steps", flush=True)
    reps = {name: Replay(mod, rec) for name, mod in mods.items()}
    for name, r in reps.items():  # compile
        r.run()
        print(f"compiled {name}", flush=True)
    steps = len(rec["t1"])
    counts = {}
    if counting:
        cnt = reps.pop("count")
        cnt.run()
        counts = {c: float(cnt.k.tmp[C0 + i]) / steps for i, c in enumerate(COUNTERS)}
        print("per call:", {k: round(v, 2) for k, v in counts.items()}, flush=True)
    cpu: dict[str, list[float]] = {k: [] for k in reps}
    for rd in range(a.rounds):
        items = list(reps.items())
        for name, r in items if rd % 2 == 0 else items[::-1]:
            cpu[name].append(1e6 * r.run() / steps)
    med = {k: float(np.median(v)) for k, v in cpu.items()}
    base = med["plain"]
    checks = {k: same_contacts(reps["plain"], r) for k, r in reps.items() if k != "plain"}
    parts = {k[3:]: med[k] - base for k in med if k.startswith("x2 ")}
    for k, v in med.items():
        print(f"{k}: {v:.2f} us per call (rounds {', '.join(f'{x:.1f}' for x in cpu[k])})", flush=True)
    for k, v in parts.items():
        print(f"  part {k}: {v:.2f} us ({100 * v / base:.0f} %) {checks['x2 ' + k]}", flush=True)
    out = {
        "what": "the seat motor's flank kernel (find_packed) on a recorded replay of its default run: us of CPU per "
        "call per variant (median of interleaved rounds), each part's cost as what doing it twice adds, and the "
        "counts per call",
        "warm_s": a.warm_s,
        "steps": steps,
        "timestep_s": rec["dt"],
        "rounds": a.rounds,
        "load_average_at_start": load0,
        "load_average_after": os.getloadavg(),
        "us_per_call": med,
        "us_per_call_rounds": cpu,
        "part_us": parts,
        "part_share": {k: v / base for k, v in parts.items()},
        "counts_per_call": counts,
        "base": a.base or "this commit",
        "other": a.other,
        "contacts_check": checks,
    }
    if a.other:
        out["other_over_base"] = med["other"] / base
        out["other_over_base_rounds"] = [x / y for x, y in zip(cpu["other"], cpu["plain"], strict=True)]
        # the rounds' own ratios (each round runs both back to back): robust where the machine's speed drifts
        out["other_over_base_median_of_rounds"] = float(np.median(out["other_over_base_rounds"]))
        print("other / base:", out["other_over_base"], out["other_over_base_rounds"], checks["other"], flush=True)
    if a.record:
        cmd = "python studies/kernel_replay.py" + "".join(f" {x}" for x in sys.argv[1:])
        write_record(a.record, out, prov=provenance(cmd))


if __name__ == "__main__":
    main()
