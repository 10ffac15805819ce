"""The unscaled seat motor's step cost against its results, per lever (issue 33 item 4), variants interleaved in one
process: MuJoCo's Newton tolerance (wormsim.contact3d.mjcf.SOLVER_TOLERANCE), old and new.

Per variant and round: the seat motor at 36 rpm (exact flanks, unscaled, the default step) over --seconds simulated,
samples as the 20 s run records them (record_every 156 at 6.4e-6 s), the CPU seconds of the stepping thread per
simulated second (time.thread_time around runner.run_model: the compiled loop runs in this thread); then, once per
variant, the seat motor's CI run (tests/contact3d/test_seeds_pieces.py's CI configuration with exact flanks: 1800
rpm, 0.25 s) and its results: F_t mean and p2p, efficiency, ratio, TE p2p.

    .venv/bin/python studies/measure_step_levers.py [--seconds 0.3] [--rounds 2] [--variant 1e-10 --variant 1e-8]

A variant is a tolerance; the first is the reference of the ratios. Before the rounds, one short run warms the
caches (numba's, the flank grid's).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
KEYS = ("tangential_force_mean_n", "tangential_force_p2p_n", "efficiency", "ratio", "transmission_error_p2p_urad")


def run_cpu(overrides: list[str], name: str = "seat_motor") -> tuple[float, dict, float]:
    """The seed's run with the overrides: (CPU s of this thread in the run, its summary, the simulated s)."""
    from wormsim.contact3d.mjcf import build_model
    from wormsim.contact3d.runner import run_model
    from wormsim.scenario import load_scenario

    bm = build_model(load_scenario(ROOT / "scenarios" / f"{name}.yaml", overrides))
    c0 = time.thread_time()
    res = run_model(bm)
    return time.thread_time() - c0, res.summary, res.sim_time_s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=0.3)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--variant", action="append", default=[])
    ap.add_argument("--no-ci", action="store_true")
    a = ap.parse_args()
    from wormsim.contact3d import mjcf

    names = a.variant or ["1e-10", "1e-8"]

    def use(v: str) -> None:
        mjcf.SOLVER_TOLERANCE = float(v)

    speed = ["contact.geometry=flanks", "simulation.mass_scaling=1", f"simulation.duration_s={a.seconds}"]
    speed += ["simulation.record_every=156"]
    sys.path.insert(0, str(ROOT))
    from tests.contact3d.test_seeds_pieces import CI

    print(f"load average {os.getloadavg()}", flush=True)
    run_cpu([*speed[:2], "simulation.duration_s=0.002"])  # warm-up
    cpu: dict[str, list[float]] = {v: [] for v in names}
    for r in range(a.rounds):
        for v in names:
            use(v)
            c, s, sim = run_cpu(speed)
            cpu[v].append(c / sim)
            print(f"round {r} {v}: {c / sim:.2f} CPU s per simulated s (36 rpm, {sim:.3f} s)", flush=True)
    for v in names:
        print(f"{v}: CPU s per simulated s {[round(x, 2) for x in cpu[v]]}")
    for v in names[1:]:
        print(f"ratio {v} / {names[0]}: {[round(x / y, 3) for x, y in zip(cpu[v], cpu[names[0]])]}")
    if a.no_ci:
        return
    base = None
    for v in names:
        use(v)
        c, s, sim = run_cpu([*CI["seat_motor"], "contact.geometry=flanks"])
        vals = {k: s[k] for k in KEYS}
        print(f"CI run, {v}: {c / sim:.2f} CPU s per simulated s; " + ", ".join(f"{k} {v!r}" for k, v in vals.items()))
        if base is None:
            base = vals
        else:
            print(
                "  relative to the first: " + ", ".join(f"{k} {(vals[k] - base[k]) / abs(base[k]):+.2e}" for k in KEYS)
            )
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
