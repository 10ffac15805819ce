"""The seeds' CI runs with exact flanks (the configurations of tests/contact3d/test_seeds_pieces.py, `contact.geometry:
flanks`): their summaries as the record docs/data/ci_seeds_flanks.json, which README's contact-pattern table renders
(tools.docs_render). About two minutes on 2 cores.

    .venv/bin/python studies/ci_seeds.py
"""

from __future__ import annotations

import sys
from pathlib import Path

from wormsim.contact3d.runner import simulate
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    sys.path.insert(0, str(ROOT))
    from tests.contact3d.test_seeds_pieces import CI

    runs = {}
    for name, sets in CI.items():
        overrides = [*sets, "contact.geometry=flanks"]
        s = simulate(load_scenario(ROOT / "scenarios" / f"{name}.yaml", overrides)).summary
        keep = {k: v for k, v in s.items() if isinstance(v, int | float | str | bool | list) and k != "wall_time_s"}
        runs[name] = {"overrides": overrides, "summary": keep}
        print(name, flush=True)
    record("ci_seeds_flanks", {"runs": runs})


if __name__ == "__main__":
    main()
