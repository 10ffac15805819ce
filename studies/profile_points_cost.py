"""What the flank grid's points along the profile cost (docs/decisions/0060-128-profile-points.md): for each
--n-profile value (wormsim.tooth.grid.N_PROFILE) in one process, interleaved over --rounds rounds (thread CPU,
medians): the flank kernel per call on studies/kernel_replay.py's recorded replay of the unscaled seat motor (its
defaults, 32 slices; the replay recorded with that grid), the seat motor's whole run at 36 rpm unscaled in CPU s per
simulated s (studies/measure_step_levers.run_cpu, as studies/flank_contacts.py), and the grid's own build
(wormsim.tooth.grid._flank_grid, uncached) for the screw jack and the seat motor at 32 slices.

    .venv/bin/python studies/profile_points_cost.py [--n-profile 64 128] [--rounds 4] [--seconds 0.2] [--record NAME]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studies import kernel_replay as kr  # noqa: E402
from studies.measure_step_levers import run_cpu  # noqa: E402
from wormsim.results.provenance import record  # noqa: E402
from wormsim.tooth import grid  # noqa: E402

REPLAY_STEPS = 3000
STEP_S = 6.4e-6  # the seat motor's default step


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-profile", type=int, nargs="+", default=[64, 128])
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=0.2)
    ap.add_argument("--record")
    a = ap.parse_args()
    from meshgen.geometry import derive
    from wormsim.scenario import load_scenario

    load0 = os.getloadavg()
    ns = a.n_profile
    mod = kr.load_module("plain", kr.KERNEL.read_text())
    reps, contacts = {}, {}
    speed = ["contact.geometry=flanks", "simulation.mass_scaling=1", f"simulation.duration_s={a.seconds}"]
    speed += ["simulation.record_every=156"]
    for n in ns:
        grid.N_PROFILE = n
        reps[n] = kr.Replay(mod, kr.record(0.05, REPLAY_STEPS))
        reps[n].run()  # compile
        contacts[n] = float(reps[n].n.mean())
        run_cpu([*speed[:2], "simulation.duration_s=0.002"])  # warm-up
    kernel_us: dict[int, list[float]] = {n: [] for n in ns}
    run_s: dict[int, list[float]] = {n: [] for n in ns}
    for rd in range(a.rounds):
        for n in ns if rd % 2 == 0 else ns[::-1]:
            grid.N_PROFILE = n
            kernel_us[n].append(reps[n].run() / REPLAY_STEPS * 1e6)
            c, _, sim = run_cpu(speed)
            run_s[n].append(c / sim)
            print(f"round {rd} N {n}: kernel {kernel_us[n][-1]:.1f} us per call, run {c / sim:.2f} CPU s per sim s")
    grid_s: dict[str, dict[int, list[float]]] = {}
    for name in ("screw_jack", "seat_motor"):
        g = derive(load_scenario(ROOT / "scenarios" / f"{name}.yaml").gear)
        grid_s[name] = {n: [] for n in ns}
        for rd in range(3):
            for n in ns if rd % 2 == 0 else ns[::-1]:
                t0 = time.process_time()
                grid._flank_grid(g, 32, n)
                grid_s[name][n].append(time.process_time() - t0)
    med = {
        n: {"kernel_us_per_call": float(np.median(kernel_us[n])), "run_cpu_s_per_sim_s": float(np.median(run_s[n]))}
        for n in ns
    }
    for n in ns:
        med[n]["run_us_per_step"] = med[n]["run_cpu_s_per_sim_s"] * STEP_S * 1e6
        med[n]["grid_build_s"] = {k: float(np.median(v[n])) for k, v in grid_s.items()}
        med[n]["slice_contacts_per_call"] = contacts[n]
    out = {
        "n_profile": ns,
        "rounds": a.rounds,
        "seconds": a.seconds,
        "load_average_at_start": load0,
        "load_average_after": os.getloadavg(),
        "kernel_us_per_call": {str(n): v for n, v in kernel_us.items()},
        "run_cpu_s_per_sim_s": {str(n): v for n, v in run_s.items()},
        "grid_build_s": {k: {str(n): v for n, v in d.items()} for k, d in grid_s.items()},
        "median": {str(n): v for n, v in med.items()},
    }
    if a.record:
        record(a.record, out)
    print(med)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
