"""The sweep's cluster: a dask LocalCluster of forked workers (or an existing scheduler), started while the client
imports and validates the sweep file, and closed beside sweep.png.

This module imports nothing heavy at its top (no dask, numpy, pydantic or simulation module): `wormsim sweep` calls
`early_fork_server` before it imports the rest of wormsim, so the local cluster's fork server (a second process
that preloads the workers' imports and compiled kernels) starts at once and does its work on another core while
the client imports, parses and validates (docs/sweeps.md, "Execution").
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Iterable
from pathlib import Path

from wormsim.exceptions import ScenarioError

SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
CONNECT_TIMEOUT_S = 20.0  # to reach an existing scheduler
WORKER_WAIT_S = 60.0  # for the first worker of an existing cluster
PEEK_MAX_BYTES = 1_000_000  # a sweep file or base scenario larger than this is not peeked at (load_sweep reads it)

# The local cluster's workers are forked from multiprocessing's fork server (a clean single-threaded process that
# imports distributed once) instead of spawned, each a fresh interpreter: a worker then starts without its own
# interpreter start-up, and ends with os._exit, without Python's finalization of a process that holds numba's and
# MuJoCo's state (about 0.8 s each; the cluster's close waited for it). Measured on the 2-CPU machine under load,
# 2 workers with the warm-up: start 3.5 s -> 1.9 s, close 2.3 s -> 0.1 s. A worker that the nanny restarts after a
# death starts by dask's default (spawn).
LOCAL_START_METHOD = "forkserver"

# dask settings of the local cluster (its scheduler, nannies and workers; the nannies hand them to their workers):
# what runs beside the points takes less CPU from them. Traced on the 2-core machine (studies/trace_sweep_cpu.py,
# docs/sweeps.md "Where the CPU goes"): with dask's defaults each worker's event loop took about 5 % of a core
# during the points, most of it the statistical profiler's 100 samples a second of every thread's stack, and the
# client's loop (scheduler, nannies, client) another 5 %: CPU the other busy worker lacks. The profile feeds
# only the dashboard, which a sweep does not show; work stealing and the active memory manager have nothing to do
# (no more tasks in flight than threads, no data kept on the workers); the memory monitors (100 ms) and the event
# loops' health tick (20 ms) run less often.
LOCAL_DASK_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "1s",
    "distributed.admin.tick.interval": "500ms",
    "distributed.scheduler.work-stealing": False,
    "distributed.scheduler.active-memory-manager.start": False,
}


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def may_run_contact3d(model: str | None, swept: Iterable[str]) -> bool:
    """Whether a sweep's points may run at contact3d: its base scenario's model (after the sweep's `set`; a
    scenario without one runs contact3d), or `model` among the swept paths. Such a sweep's fork server preloads
    the compiled kernels (wormsim.sweep.preload_warm)."""
    return (model or "contact3d") == "contact3d" or "model" in set(swept)


def start_fork_server(warm: bool) -> None:
    """Start multiprocessing's fork server now, preloading the workers' imports (wormsim.sweep.preload) and with
    `warm` the compiled contact3d kernels (wormsim.sweep.preload_warm), once for all workers, on another core while
    this process imports and validates. A server that runs already (started by early_fork_server, or by an earlier
    sweep in this process) is kept."""
    import multiprocessing
    from multiprocessing import forkserver

    multiprocessing.set_forkserver_preload(["wormsim.sweep.preload_warm" if warm else "wormsim.sweep.preload"])
    forkserver.ensure_running()


def stop_fork_server() -> None:
    """Stop the fork server this process started (an invalid sweep file: its preload, a compile on a fresh machine
    among it, is not waited for). Workers forked from it keep running; a later sweep starts a new server."""
    import signal
    from multiprocessing import forkserver

    server = forkserver._forkserver  # (multiprocessing has no public stop; ForkServer._stop waits for the exit)
    pid = getattr(server, "_forkserver_pid", None)
    if pid is None:
        return
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        pass
    try:
        server._stop()  # type: ignore[attr-defined]
    except (AttributeError, OSError, ChildProcessError):
        pass


def _peek_node(node, key: str):
    """The value node of `key` in a YAML mapping node (None where node is not a mapping or has no such key)."""
    import yaml

    if not isinstance(node, yaml.MappingNode):
        return None
    return next((v for k, v in node.value if isinstance(k, yaml.ScalarNode) and k.value == key), None)


def _peek_keys(node) -> list[str]:
    import yaml

    if not isinstance(node, yaml.MappingNode):
        return []
    return [k.value for k, _ in node.value if isinstance(k, yaml.ScalarNode)]


def peek_contact3d(sweep_path: str | Path) -> bool | None:
    """may_run_contact3d from the sweep file and its base scenario as YAML nodes (yaml.compose: no alias expanded,
    no value built), before wormsim.sweep.spec is imported; None where either cannot be read (load_sweep then says
    why, with exit 2)."""
    import yaml

    try:
        path = Path(sweep_path)
        if path.stat().st_size > PEEK_MAX_BYTES:
            return None
        doc = yaml.compose(path.read_text(), Loader=yaml.SafeLoader)
        base = _peek_node(doc, "base")
        if not isinstance(base, yaml.ScalarNode):
            return None
        base_path = path.parent / base.value
        if base_path.stat().st_size > PEEK_MAX_BYTES:
            return None
        model_node = _peek_node(_peek_node(doc, "set"), "model") or _peek_node(
            yaml.compose(base_path.read_text(), Loader=yaml.SafeLoader), "model"
        )
    except (OSError, ValueError, yaml.YAMLError):
        return None
    model = model_node.value if isinstance(model_node, yaml.ScalarNode) else None
    swept = _peek_keys(_peek_node(doc, "grid")) + _peek_keys(_peek_node(doc, "zip"))
    return may_run_contact3d(model, swept)


def early_fork_server(sweep_path: str | Path, scheduler: str | None) -> bool:
    """`wormsim sweep`'s first step, before it imports the rest of wormsim: start the local cluster's fork server
    (start_fork_server, warm when peek_contact3d says the points may run at contact3d). Nothing for a cluster by
    address, or a sweep file that cannot be peeked at. Returns whether a server was started."""
    if scheduler or os.environ.get(SCHEDULER_ENV):
        return False
    contact3d = peek_contact3d(sweep_path)
    if contact3d is None:
        return False
    start_fork_server(contact3d)
    return True


def open_client(scheduler: str | None, workers: int | None, warm: bool = False):
    """(client, cluster or None, info). scheduler None: a LocalCluster of `workers` single-threaded processes, with
    `warm` each of them given the plugin wormsim.sweep.warm.WarmKernels when it is made (a worker forked from the
    warm fork server skips it; one the nanny restarts loads the kernels before it registers), so that warm_workers
    has nothing to register (info "warm_at_start"). Raises ScenarioError for a bad --workers or a scheduler that does
    not answer."""
    if workers is not None and workers < 1:
        raise ScenarioError(f"--workers {workers}: allowed an integer >= 1")
    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    if scheduler:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError) as exc:
            raise ScenarioError(
                f"--scheduler {scheduler}: no dask scheduler answered within {CONNECT_TIMEOUT_S:g} s "
                f"({exc.__class__.__name__}); start one with `dask scheduler` or leave "
                f"--scheduler and {SCHEDULER_ENV} unset for a local cluster"
            ) from None
        try:
            client.wait_for_workers(workers or 1, timeout=WORKER_WAIT_S)
        except TimeoutError:
            client.close()
            raise ScenarioError(
                f"--scheduler {scheduler}: fewer than {workers or 1} workers connected within "
                f"{WORKER_WAIT_S:g} s (start them with `dask worker {scheduler}`)"
            ) from None
        cluster, kind = None, "existing scheduler"
    else:
        import dask

        n = workers or default_workers()
        # dask's own log lines stay off stderr up to ERROR: on a loaded machine a worker's heartbeat times out and
        # distributed logs it with a traceback, though the worker reconnects and the sweep ends well (a point that
        # fails, or a lost worker, is a row with its message in sweep.csv / sweep.json)
        plugins: tuple = ()
        if warm:
            from wormsim.sweep.warm import WarmKernels

            plugins = (WarmKernels(),)
        with dask.config.set({"distributed.worker.multiprocessing-method": LOCAL_START_METHOD, **LOCAL_DASK_CONFIG}):
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",
                silence_logs=logging.CRITICAL,
                plugins=plugins,
            )
        client = Client(cluster)
        kind = "LocalCluster (processes)"
    ws = client.scheduler_info().get("workers", {})
    info = {
        "kind": kind,
        "warm_at_start": bool(warm and cluster is not None),
        "scheduler": client.scheduler.address,
        "start_s": time.perf_counter() - t0,
        "workers": len(ws),
        "threads": sum(w.get("nthreads", 0) for w in ws.values()),
        "worker_list": [
            {"address": a, "nthreads": w.get("nthreads"), "memory_limit": w.get("memory_limit")} for a, w in ws.items()
        ],
    }
    return client, cluster, info


def warm_workers(client, info: dict) -> None:
    """Every worker loads (the machine's first compiles, once) the contact3d kernels before the points go out
    (wormsim.sweep.warm.WarmKernels; also on workers that join later). info gets "warm_s". Nothing to do where the
    workers got the plugin when they were made (open_client's `warm`): no round trip to every worker before the
    first point."""
    from wormsim.sweep.warm import WarmKernels

    t0 = time.perf_counter()
    if info.get("warm_at_start"):
        info["warm_s"] = 0.0
        return
    try:
        client.register_plugin(WarmKernels())
    except Exception:  # (a worker that cannot warm compiles or loads in its first point)
        pass
    info["warm_s"] = time.perf_counter() - t0


def plot_imports() -> None:
    """matplotlib's import (pyplot on the Agg backend, what sweep.png needs). A local cluster's start thread runs it
    before distributed's import: one thread imports both. Two threads that import them at once can stop the command
    with importlib's _DeadlockError (CPython's per-module locks taken in opposite orders for a package and its
    submodule: pyparsing imports `html`, whose __init__ imports `html.entities`, which tornado imports directly). That
    start waits for the fork server's preload on another core, so the import costs it no time. On a cluster given by
    address nothing waits for a preload: the client connects first and imports matplotlib in its main thread once
    the first points are out (runner.run_sweep; distributed is imported and connected by then), while the workers
    run them. A failure is dropped (the figure imports for itself)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.backends.backend_agg  # noqa: F401  (savefig's PNG)
        import matplotlib.pyplot  # noqa: F401
    except Exception:
        pass


class ClusterStart:
    """open_client in a thread, started before the sweep file is validated (the cluster's start overlaps it);
    `get()` waits for it (and re-raises its error; `used` then True), `close()` closes what it opened."""

    def __init__(self, scheduler: str | None, workers: int | None, warm: bool = True):
        import threading

        self._result: tuple | None = None
        self._error: BaseException | None = None
        self.used = False
        scheduler = scheduler or os.environ.get(SCHEDULER_ENV) or None
        if scheduler is None:
            start_fork_server(warm)
        self._thread = threading.Thread(
            target=self._run, args=(scheduler, workers, warm), name="wormsim-cluster-start", daemon=True
        )
        self._thread.start()

    def _run(self, scheduler, workers, warm) -> None:
        if scheduler is None:  # (beside the fork server's preload; with a scheduler the points run first: run_sweep)
            plot_imports()
        try:
            self._result = open_client(scheduler, workers, warm)
        except BaseException as exc:  # (re-raised by get in the main thread)
            self._error = exc

    def get(self):
        self.used = True
        self._thread.join()
        if self._error is not None:
            raise self._error
        assert self._result is not None
        return self._result

    def close(self) -> None:
        self._thread.join()
        if self._result is not None:
            close_cluster(self._result[0], self._result[1])


def close_cluster(client, cluster) -> None:
    """Close the client, then the local cluster (its scheduler, nannies and workers); errors are dropped."""
    try:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    except Exception:  # (closing a cluster after Ctrl-C may fail; the tables are written)
        pass
