"""contact3d (exact flanks) on the screw jack at its working point with a shaft angle of 0, +0.1 and -0.1 deg: the
loaded pattern, pressure, fluctuation, TE and play (docs/errors.md section 6; the torsional level's loaded TCA is
checked against these in tests/torsional/test_errors.py). Writes the record docs/data/errors_shaft_angle.json.

    .venv/bin/python studies/errors_shaft_angle.py
"""

from __future__ import annotations

import sys
from pathlib import Path

from wormsim.contact3d.runner import simulate
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "studies"))
from errors_study import KEYS, RUNS  # noqa: E402  (the study's short coarse runs and outputs)

ANGLES_DEG = (0.0, 0.1, -0.1)


def main() -> None:
    rows = []
    base = ["contact.geometry=flanks", *RUNS["screw_jack"]]
    for a in ANGLES_DEG:
        s = simulate(
            load_scenario(ROOT / "scenarios" / "screw_jack.yaml", [*base, f"errors.shaft_angle_deg={a}"])
        ).summary
        rows.append({"shaft_angle_deg": a, **{k: s.get(k) for k in KEYS}})
        print(rows[-1], flush=True)
    record("errors_shaft_angle", {"scenario": "scenarios/screw_jack.yaml", "overrides": base, "rows": rows})


if __name__ == "__main__":
    main()
