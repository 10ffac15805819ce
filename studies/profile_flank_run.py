"""Where a flank run's simulate() spends its CPU outside the stepping loop: the bench's case (wormsim.bench.cases, the
screw jack's medium flanks at --factor times the default step, the call `wormsim bench` times) after a warm-up run,
each part's thread CPU seconds (time.thread_time around the runner's and the contact pattern's functions), medians and
minima over --rounds runs in one process. "rest" is the total less the parts outside the pattern's (FlankSource.finish
holds pattern.summary and pattern.grid).

    .venv/bin/python studies/profile_flank_run.py [--scenario screw_jack] [--factor 2] [--rounds 5]

Compare two trees as interleaved processes (the machine is shared: compare ratios in one run, never across runs).
"""

from __future__ import annotations

import argparse
import collections
import statistics
import time

PARTS = (  # (module, attribute, label): the functions timed
    ("runner", "build_model", "build_model"),
    ("sources.FlankSource", "__init__", "source init"),
    ("runner", "_loop", "loop"),
    ("contact_sums.RadiusLog", "efficiency", "rlog.efficiency"),
    ("runner", "_stiffness_outputs", "stiffness_outputs"),
    ("runner", "_run_summary", "run_summary"),
    ("hertz.PatternLog", "summary", "pattern.summary"),
    ("hertz.PatternLog", "grid", "pattern.grid"),
    ("runner", "_after_run_keys", "after_run_keys"),
)
INSIDE_FINISH = ("pattern.summary", "pattern.grid")


def _wrap(obj, name: str, label: str, acc: dict) -> None:
    f = getattr(obj, name)

    def timed(*a, **k):
        c0 = time.thread_time()
        try:
            return f(*a, **k)
        finally:
            acc[label] += time.thread_time() - c0

    setattr(obj, name, timed)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="screw_jack")
    ap.add_argument("--factor", type=float, default=2.0)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()

    from wormsim.bench.cases import bench_cases
    from wormsim.contact3d import contact_sums, runner, sources
    from wormsim.tooth import hertz

    mods = {"runner": runner, "sources": sources, "contact_sums": contact_sums, "hertz": hertz}
    acc: dict = collections.defaultdict(float)
    for path, name, label in PARTS:
        head, *tail = path.split(".")
        obj = mods[head]
        for t in tail:
            obj = getattr(obj, t)
        _wrap(obj, name, label, acc)
    cases = bench_cases(
        False, models=("contact3d",), scenarios=(args.scenario,), geometries=("flanks",), resolutions=("medium",)
    )
    case = next(c for c in cases if c.timestep_factor == args.factor and not c.finer)
    sc = case.build()
    runner.simulate(sc)  # the warm-up: caches and compiled code loaded
    rows = collections.defaultdict(list)
    for _ in range(args.rounds):
        acc.clear()
        c0 = time.thread_time()
        res = runner.simulate(sc)
        total = time.thread_time() - c0
        rows["TOTAL"].append(total)
        rows["outside the loop"].append(total - acc["loop"])
        for k, v in acc.items():
            rows[k].append(v)
        rows["rest"].append(total - sum(v for k, v in acc.items() if k not in INSIDE_FINISH))
    print(f"{args.scenario} flanks medium, {args.factor:g} x the default step ({res.steps} steps), thread CPU s")
    for k, v in rows.items():
        print(f"{k:20s} median {statistics.median(v):.4f}  min {min(v):.4f}")


if __name__ == "__main__":
    main()
