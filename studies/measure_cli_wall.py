"""Wall time of the whole `wormsim run` (model, loop, report.png, recording) of the full 20 s seat motor with
`simulation.mass_scaling: auto` (docs/performance.md, the speed targets): one warm-up run (numba's cache, the flank
grid), then `--repeats` timed runs of the console script in a subprocess. Writes docs/data/cli_wall.json.

    .venv/bin/python studies/measure_cli_wall.py [--repeats 2]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from wormsim.results.provenance import record

ROOT = Path(__file__).resolve().parents[1]
ARGS = ["run", "scenarios/seat_motor.yaml", "--set", "simulation.mass_scaling=auto", "--no-progress"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=2)
    repeats = ap.parse_args().repeats
    exe = str(Path(sys.executable).with_name("wormsim"))
    walls = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeats + 1):
            out = Path(tmp) / f"run{i}"
            t0 = time.perf_counter()
            subprocess.run([exe, *ARGS, "--out", str(out)], cwd=ROOT, check=True, capture_output=True)
            wall = time.perf_counter() - t0
            if i:
                walls.append(wall)
            print(i, wall, flush=True)
            shutil.rmtree(out)
    print(record("cli_wall", {"command": "wormsim " + " ".join(ARGS) + " --out DIR", "wall_s": walls}))


if __name__ == "__main__":
    main()
