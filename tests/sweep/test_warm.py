"""wormsim.sweep.warm: after a worker's warm-up (what the fork server does once for every worker), a contact3d point
loads no compiled function of its own: its first point costs what its others cost."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from wormsim.sweep.warm import SAMPLED_STEPS

ROOT = Path(__file__).resolve().parents[2]

_POINT_AFTER_WARM = """
import json, sys
from wormsim.runtime import jit_cache
from wormsim.scenario import load_scenario
from wormsim.sweep.runner import run_point
from wormsim.sweep.warm import warm_worker

warm = warm_worker()
sc = load_scenario(sys.argv[1], ["model=contact3d", "simulation.duration_s=0.05", "drive.speed_rpm=2000"])
before = jit_cache.dispatcher_stats()
status = run_point(sc.model_dump(mode="json"), False)["summary"]["status"]
print(json.dumps([warm, status, before, jit_cache.dispatcher_stats()]))
"""


def test_a_point_after_the_warm_up_loads_no_compiled_function():
    """A 0.05 s screw-jack point (about 1400 steps: its samples' guards, friction, series and the friction check)
    after warm_worker: numba's counters (signatures loaded from the cache, or compiled) do not move."""
    assert SAMPLED_STEPS >= 100
    cp = subprocess.run(
        [sys.executable, "-c", _POINT_AFTER_WARM, str(ROOT / "scenarios" / "screw_jack.yaml")],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert cp.returncode == 0, cp.stderr
    warm, status, before, after = json.loads(cp.stdout.splitlines()[-1])
    assert warm["error"] is None and status == "ok"
    assert (after["hits"], after["misses"]) == (before["hits"], before["misses"]), (before, after)
