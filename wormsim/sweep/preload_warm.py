"""wormsim.sweep.preload and the compiled contact3d kernels (wormsim.sweep.warm.warm_worker: the machine's first
process compiles them, the others load) in the fork server, once for every worker forked from it. warm_worker
drops its own failures (a worker then loads or compiles in its first point)."""

from __future__ import annotations

from wormsim.sweep import preload  # noqa: F401
from wormsim.sweep.warm import warm_worker

WARM = warm_worker()
