"""The unscaled seat motor's result-moving levers against its CPU (issue 33 item 4: at most 10 s per simulated
second), none of them the default: a larger step (simulation.timestep_s 8e-6, 0.5 x the stable limit against the
default 0.4), fewer slices (contact.slices 24 against the medium 32), fewer MuJoCo contacts (contact.flank_contacts
2 against 4).

Per variant and round: the seat motor at its defaults (36 rpm, exact flanks, unscaled, record_every 156) over
--seconds simulated from rest, CPU seconds of the stepping thread per simulated second (studies/measure_step_levers.
run_cpu), the variants interleaved over --rounds; then once per variant the seat motor's CI run
(tests/contact3d/test_seeds_pieces.py's CI configuration with exact flanks) and its results relative to the default.

    .venv/bin/python studies/seat_motor_levers.py [--seconds 0.1] [--rounds 2] [--record seat_motor_levers]
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = {
    "default": [],
    "timestep 8e-6 s (0.5 x limit)": ["simulation.timestep_s=8e-6"],
    "24 slices": ["contact.slices=24"],
    "flank_contacts 2": ["contact.flank_contacts=2"],
}
KEYS = ("tangential_force_mean_n", "tangential_force_p2p_n", "efficiency", "transmission_error_p2p_urad")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=0.1)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--record", default="")
    a = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from studies.measure_step_levers import run_cpu
    from tests.contact3d.test_seeds_pieces import CI
    from wormsim.results.provenance import provenance, record

    load0 = os.getloadavg()
    speed = ["contact.geometry=flanks", "simulation.mass_scaling=1", "simulation.record_every=156"]
    for v in VARIANTS.values():  # warm-up: each variant's compiled path and flank grid
        run_cpu([*speed, *v, "simulation.duration_s=0.002"])
    cpu: dict[str, list[float]] = {k: [] for k in VARIANTS}
    for r in range(a.rounds):
        items = list(VARIANTS.items())
        for k, v in items if r % 2 == 0 else items[::-1]:
            c, _, sim = run_cpu([*speed, *v, f"simulation.duration_s={a.seconds}"])
            cpu[k].append(c / sim)
            print(f"round {r} {k}: {c / sim:.2f} CPU s per simulated s", flush=True)
    results: dict[str, dict] = {}
    for k, v in VARIANTS.items():
        _, s, _ = run_cpu([*CI["seat_motor"], "contact.geometry=flanks", *v])
        results[k] = {x: s[x] for x in KEYS} | {"timestep_s": s["timestep_s"], "flank_slices": s["flank_slices"]}
        results[k]["contacts_mean"] = s["contacts_mean"]
        print(k, results[k], flush=True)
    base = results["default"]
    out = {
        "what": "the unscaled seat motor's CPU s per simulated s per result-moving lever (interleaved rounds, 36 rpm, "
        "from rest) and the seat motor's CI run per lever relative to the default",
        "seconds": a.seconds,
        "rounds": a.rounds,
        "load_average_at_start": load0,
        "load_average_after": os.getloadavg(),
        "cpu_s_per_sim_s": cpu,
        "ratio_to_default": {k: [x / y for x, y in zip(c, cpu["default"])] for k, c in cpu.items()},
        "ci": results,
        "ci_relative_pct": {k: {x: (r[x] / base[x] - 1) * 100 for x in KEYS} for k, r in results.items()},
    }
    if a.record:
        cmd = "python studies/seat_motor_levers.py" + "".join(f" {x}" for x in sys.argv[1:])
        record(a.record, out, prov=provenance(cmd))


if __name__ == "__main__":
    main()
