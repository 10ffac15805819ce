"""The local cluster's fork server imports this module before it forks the first worker (multiprocessing's
forkserver preload, set by wormsim.sweep.cluster.start_fork_server): the workers' imports (distributed's worker,
wormsim's run entry) are then in the server once, and every worker forked from it starts with them. `wormsim sweep`
starts the server first (wormsim.sweep.cluster.early_fork_server), so this runs on another core while the client
imports and validates the points. A sweep with
contact3d points preloads wormsim.sweep.preload_warm instead, which also loads the compiled kernels."""

from __future__ import annotations

import os

# before numpy is imported here: OpenBLAS's threads sleep as soon as a call ends instead of spinning for about
# 2^28 cycles (0.1 s) after it; a point's summary calls a threaded complex dot product (the mesh line's amplitudes)
# several times, and each call left a thread spinning on the other core (about 0.13 CPU-s per point, traced with
# 2 workers on 2 cores). The number of threads, hence every result bit, stays as in `wormsim run` on the machine:
# dask's nanny sets OPENBLAS_NUM_THREADS=1 only in the workers it spawns, after this server imported numpy.
os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")
# a worker draws nothing with MuJoCo: its import then skips the GLFW probe (which starts a Python subprocess)
os.environ.setdefault("MUJOCO_GL", "disable")

import distributed.nanny  # noqa: F401  (the worker's own imports, once in the server)
import distributed.worker  # noqa: F401
from distributed.versions import get_versions

import wormsim.rating.rate  # noqa: F401  (a run's plausibility warnings rate the wheel's pressure)
import wormsim.run  # noqa: F401
import wormsim.sweep.runner  # noqa: F401  (the tasks' functions: a worker unpickles its first task with them)

# what a worker tells the scheduler when it registers (platform.uname's processor, a `uname -p` subprocess, and the
# packages' versions from their metadata: 0.01-0.03 s), cached per process: once here, not in every forked worker
# between its fork and its first point
get_versions()
