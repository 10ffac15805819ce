"""MuJoCo contacts per tooth flank (`contact.flank_contacts`: slice, N per flank, tooth) against their cost and
results (issue 33 item 4: the unscaled seat motor's step; issue 31: F_t p2p within 10 % of per-slice).

Speed: the seat motor at 36 rpm (exact flanks, unscaled, the default step), --seconds simulated, samples as the 20 s run
records them (record_every 156), CPU seconds of the stepping thread per simulated second (time.thread_time around
runner.run_model: the compiled loop runs in this thread), the variants interleaved over --rounds in one process.
Results: each seed's CI run (tests/contact3d/test_seeds_pieces.py's CI configuration, exact flanks) per variant: F_t
mean and p2p, efficiency, TE p2p, p_H max, F_r, the MuJoCo contacts per step; relative to per slice.

    .venv/bin/python studies/flank_contacts.py [--seconds 0.3] [--rounds 2] [--record flank_contacts]
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = ("slice", "4", "2", "tooth")
KEYS = (
    "tangential_force_mean_n",
    "tangential_force_p2p_n",
    "efficiency",
    "transmission_error_p2p_urad",
    "contact_pressure_max_mpa",
    "radial_force_mean_n",
    "contacts_mean",
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=0.3)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--record", default="")
    a = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from studies.measure_step_levers import run_cpu
    from tests.contact3d.test_seeds_pieces import CI
    from wormsim.results.provenance import provenance, record

    load0 = os.getloadavg()
    speed = ["contact.geometry=flanks", "simulation.mass_scaling=1", f"simulation.duration_s={a.seconds}"]
    speed += ["simulation.record_every=156"]
    for v in VARIANTS:  # warm-up: every variant's compiled path
        run_cpu([*speed[:2], "simulation.duration_s=0.002", f"contact.flank_contacts={v}"])
    cpu: dict[str, list[float]] = {v: [] for v in VARIANTS}
    for r in range(a.rounds):
        for v in VARIANTS:
            c, _, sim = run_cpu([*speed, f"contact.flank_contacts={v}"])
            cpu[v].append(c / sim)
            print(f"round {r} {v}: {c / sim:.2f} CPU s per simulated s", flush=True)
    results: dict[str, dict[str, dict]] = {}
    for seed in CI:
        results[seed] = {}
        for v in VARIANTS:
            _, s, _ = run_cpu([*CI[seed], "contact.geometry=flanks", f"contact.flank_contacts={v}"], seed)
            results[seed][v] = {k: s[k] for k in KEYS} | {"flank_slices": s["flank_slices"]}
            print(seed, v, results[seed][v], flush=True)
    out = {
        "what": "the seat motor at 36 rpm, unscaled, samples as the 20 s run: CPU s of the stepping thread per "
        "simulated s per contact.flank_contacts variant (interleaved rounds); the seeds' CI runs per variant",
        "seconds": a.seconds,
        "rounds": a.rounds,
        "load_average_at_start": load0,
        "load_average_after": os.getloadavg(),
        "cpu_s_per_sim_s": cpu,
        "ratio_to_slice": {v: [x / y for x, y in zip(cpu[v], cpu["slice"])] for v in VARIANTS},
        "seeds": results,
    }
    if a.record:
        cmd = "python studies/flank_contacts.py" + "".join(f" {x}" for x in sys.argv[1:])
        record(a.record, out, prov=provenance(cmd))
    print({v: [round(x, 2) for x in c] for v, c in cpu.items()})


if __name__ == "__main__":
    main()
