"""The wedge level on seed 000's valve cases (docs/validation.md, "The wedge level against seed 000"): mov_1 ... mov_5
and mov_3_early_seat as shipped, their S1, S2, Kd1, Kd2 and steady speed beside seed 000's results table. Writes the
record docs/data/wedge_seed000.json (milliseconds per case).

    .venv/bin/python studies/wedge_seed000.py
"""

from __future__ import annotations

from pathlib import Path

from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.wedge import simulate

ROOT = Path(__file__).resolve().parents[1]
# seed 000's results table (also in each scenario's description): S1 [N], Kd1, S2 [N], Kd2
SEED = {
    "mov_1": (800, 0.81, -6300, 0.76),
    "mov_2": (1400, 1.4, -11300, 1.37),
    "mov_3": (1800, 1.84, -16500, 2.0),
    "mov_4": (900, 0.91, -7600, 0.92),
    "mov_5": (1500, 1.50, -12100, 1.36),
}
CASES = (*SEED, "mov_3_early_seat")
KEYS = ("S1_peak_n", "Kd1", "S2_peak_n", "Kd2", "S1_steady_n", "S2_steady_n", "speed_steady_m_s", "Ft1_n", "Ft2_n")


def main() -> None:
    runs = {}
    for name in CASES:
        sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml")
        s = simulate(sc).summary
        runs[name] = {
            "driven_mass_kg": sc.wedge.driven_mass_kg,
            "load_force_n": sc.wedge.load.force_n,
            "seed": dict(zip(("S1_n", "Kd1", "S2_n", "Kd2"), SEED[name], strict=True)) if name in SEED else None,
            **{k: s.get(k) for k in KEYS},
        }
    print(record("wedge_seed000", {"runs": runs}))


if __name__ == "__main__":
    main()
