"""The sweep's worker plugin: each dask worker loads the compiled contact3d kernels before its first point.

`WarmKernels.setup` runs on every worker that joins (distributed's WorkerPlugin, when the sweep's points include
contact3d runs: given to a local cluster's workers when they are made, before they register, and registered by the
client on a cluster given by address) in a thread of the worker, so the worker's event loop keeps answering the
scheduler: wormsim.runtime.jit_cache.ensure_warm (the machine's first worker compiles, holding the cache's lock; the
others wait for it and load), then one short run (jit_cache.WARM_RUNS' first, SAMPLED_STEPS steps: long enough for
the samples that leave the compiled stretch) and the friction check, which load every compiled function a screw-jack
point calls, numba's start-up and the imports into the worker process. A worker's first point then costs what its
others cost. A failure is dropped: the point compiles or loads for itself.
"""

from __future__ import annotations

import asyncio
import os

from distributed.diagnostics.plugin import WorkerPlugin

# the short run's steps: enough for the samples that leave the compiled stretch (the guards' and friction's Python
# path, the series' columns), which a point reaches in its first milliseconds and WARM_STEPS does not (measured on
# the screw jack: 40 steps leave 6 functions to the point, 120 none; 200 costs about 0.05 s more than 40)
SAMPLED_STEPS = 200
_warm_pid: int | None = None  # the process that ran the short run: this one, or the fork server it was forked from


def warm_pid() -> int | None:
    """The pid of the process that ran the short run in this process's memory (os.getpid(), or the fork server's
    for a worker forked from a warm one); None before it."""
    return _warm_pid


def warm_worker() -> dict:
    """ensure_warm and the short run in this process, unless done here already (a worker forked from the warm fork
    server: wormsim.sweep.preload); returns {"compiled": bool, "error": str | None, "skipped": bool}."""
    global _warm_pid
    if _warm_pid is not None:
        return {"compiled": False, "error": None, "skipped": True}
    from wormsim.contact3d.runner import _warm_friction_check, warm_runs
    from wormsim.runtime import jit_cache

    try:
        compiled = jit_cache.ensure_warm(warm_runs)
        warm_runs(jit_cache.WARM_RUNS[:1], steps=SAMPLED_STEPS)
        _warm_friction_check()  # (the machine's warm-up's own step, due later in a point than the short run)
    except Exception as exc:  # (the points compile or load for themselves)
        return {"compiled": False, "error": f"{exc.__class__.__name__}: {exc}", "skipped": False}
    _warm_pid = os.getpid()
    return {"compiled": compiled, "error": None, "skipped": False}


class WarmKernels(WorkerPlugin):
    """Loads (or, first on a machine, compiles) the contact3d kernels when a worker starts (module docstring)."""

    name = "wormsim-warm-kernels"

    async def setup(self, worker) -> None:
        await asyncio.get_running_loop().run_in_executor(None, warm_worker)
