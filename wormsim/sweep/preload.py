"""The local cluster's fork server imports this module before it forks the first worker (multiprocessing's
forkserver preload, set by wormsim.sweep.cluster.start_fork_server): the workers' imports (distributed's worker,
wormsim's run entry) are then in the server once, and every worker forked from it starts with them. `wormsim sweep`
starts the server first (wormsim.sweep.cluster.early_fork_server), so this runs on another core while the client
imports and validates the points. A sweep with
contact3d points preloads wormsim.sweep.preload_warm instead, which also loads the compiled kernels."""

from __future__ import annotations

import distributed.nanny  # noqa: F401  (the worker's own imports, once in the server)
import distributed.worker  # noqa: F401

import wormsim.rating.rate  # noqa: F401  (a run's plausibility warnings rate the wheel's pressure)
import wormsim.run  # noqa: F401
