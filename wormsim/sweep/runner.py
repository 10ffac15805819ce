"""`wormsim sweep`: run a sweep's points on dask.distributed and write DIR/sweep.csv, sweep.json, sweep.png.

Cluster: a LocalCluster of processes, one single-threaded worker per core (or `workers`), unless a scheduler
address is given (`--scheduler`, or DASK_SCHEDULER_ADDRESS). Workers get the validated scenario and return the
summary (and, with keep_runs, the result files as bytes) through the client, so they need the same wormsim
installed but no shared file system.

Rows are written as points finish (distributed.as_completed), each time by an atomic rewrite of sweep.csv, so an
interrupted sweep leaves a consistent table of the finished points. Resume: a point whose scenario_hash already
has an "ok" row in DIR/sweep.csv is not run again. A point that fails (SimulationError, a ScenarioError found
during the build, an internal error, a lost worker) is a row with status "failed" and its message.
"""

from __future__ import annotations

import csv
import io
import os
import platform
import shutil
import sys
import tempfile
import time
from importlib import metadata
from pathlib import Path

from wormsim.runfolder.writer import ResultDir, write_json_atomic
from wormsim.scenario import ScenarioError
from wormsim.sweep.cluster import (  # noqa: F401  (the cluster's names, as they were here)
    CONNECT_TIMEOUT_S,
    LOCAL_START_METHOD,
    SCHEDULER_ENV,
    WORKER_WAIT_S,
    ClusterStart,
    close_cluster,
    default_workers,
    open_client,
    plot_imports,
    start_fork_server,
    warm_workers,
)
from wormsim.sweep.spec import Point, Sweep

CSV_NAME, JSON_NAME, PNG_NAME, RUNS_DIR = "sweep.csv", "sweep.json", "sweep.png", "runs"
MAX_CHUNK = 4  # points per task at most (chunk_size)
_FIRST = ("point",)
_AFTER_SWEPT = ("status", "message")
_LAST = ("wall_time_s", "scenario_hash")
_NOT_COLUMNS = {"status", "message", "wall_time_s"}


# ----------------------------------------------------------------------------- on the worker


def run_point(scenario: dict, keep_files: bool) -> dict:
    """One point, on a worker: simulate (and with keep_files write the result folder into a temporary directory
    and return its files). Never raises for a failed simulation: returns status "failed" and the message."""
    t_start = time.time()
    cpu_start = time.thread_time()
    from wormsim.sweep.warm import warm_pid

    warmed_by = warm_pid()
    from wormsim.exceptions import SimulationError
    from wormsim.run import run_scenario, simulate
    from wormsim.scenario import Scenario

    sc = Scenario.model_validate(scenario)
    t_setup = time.time() - t_start
    base = {"model": sc.model, "scenario": sc.name}
    files: dict[str, bytes] = {}
    t0 = time.perf_counter()
    try:
        if keep_files:
            tmp = Path(tempfile.mkdtemp(prefix="wormsim-point-"))
            try:
                try:
                    summary = run_scenario(sc, tmp, progress=False)
                finally:
                    files = {f.name: f.read_bytes() for f in tmp.iterdir() if f.is_file()}
            finally:
                shutil.rmtree(tmp, ignore_errors=True)
        else:
            res = simulate(sc)
            summary = {
                "status": "ok",
                "message": "",
                **base,
                "wall_time_s": time.perf_counter() - t0,
                "sim_time_s": res.sim_time_s,
                "steps": res.steps,
                **res.summary,
            }
    except SimulationError as exc:
        summary = {"status": "failed", "message": str(exc), **base, "wall_time_s": time.perf_counter() - t0}
    except ScenarioError as exc:
        summary = {
            "status": "failed",
            "message": f"invalid input: {exc}",
            **base,
            "wall_time_s": time.perf_counter() - t0,
        }
    except Exception as exc:  # (a bug in one point must not stop the sweep)
        summary = {
            "status": "failed",
            "message": f"internal error: {exc.__class__.__name__}: {exc}",
            **base,
            "wall_time_s": time.perf_counter() - t0,
        }
    from wormsim.runtime import jit_cache

    jit = jit_cache.dispatcher_stats()
    return {
        "summary": summary,
        "files": files,
        "timing": {
            "worker": _worker_name(),
            "start": t_start,
            "end": time.time(),
            "setup_s": t_setup,
            # this thread's CPU seconds for the point: against end - start, the time it waited for a core
            "thread_cpu_s": time.thread_time() - cpu_start,
            # the pid that loaded the kernels before this point: the fork server's for a worker forked warm
            "warmed_by_pid": warmed_by,
            "pid": os.getpid(),
            # this worker process's totals so far: seconds compiling, signatures compiled / loaded
            # (wormsim.runtime.jit_cache)
            "compile_s": jit_cache.compile_seconds(),
            "jit_misses": jit["misses"],
            "jit_hits": jit["hits"],
        },
    }


def run_points(scenarios: list[dict], keep_files: bool) -> list[dict]:
    """Several points in one task (run_sweep's chunks of short points): run_point on each, in order."""
    return [run_point(sc, keep_files) for sc in scenarios]


def chunk_size(n_points: int, threads: int) -> int:
    """Points per task at most: 1, or up to MAX_CHUNK where there are at least 8 points per worker thread. A task's
    points share one scheduler round trip and one hand-back (the worker waits for its next task only once per chunk);
    a worker that dies fails the points of its chunk. 16 points on 2 workers: 2 per task."""
    if n_points < 8 * threads:
        return 1
    return max(1, min(MAX_CHUNK, n_points // (4 * threads)))


def task_sizes(n_points: int, threads: int) -> list[int]:
    """The points of each task in the order they are handed out: chunk_size(n_points, threads) while the points left
    fill at least two such tasks per thread, then fewer, down to one point per task for the last ones (guided
    self-scheduling: the workers' last tasks are single points, so no worker waits at the end for another's chunk).
    16 points on 2 workers: five tasks of 2, then six of 1."""
    most, sizes, left = chunk_size(n_points, threads), [], n_points
    while left > 0:
        sizes.append(max(1, min(most, left // (2 * threads))))
        left -= sizes[-1]
    return sizes


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError):
        return "local"


# ----------------------------------------------------------------------------- table


def _scalar(v) -> bool:
    return v is None or isinstance(v, (bool, int, float, str))


def row_of(point: Point, summary: dict) -> dict:
    row = {
        "point": point.index,
        **point.values,
        "status": summary.get("status", "failed"),
        "message": summary.get("message", ""),
    }
    row.update({k: v for k, v in summary.items() if k not in _NOT_COLUMNS and _scalar(v)})
    if summary.get("warnings"):  # the run's warnings (wormsim.results.run_warnings) as one cell
        row["warnings"] = "; ".join(summary["warnings"])
    row["wall_time_s"] = summary.get("wall_time_s")
    row["scenario_hash"] = point.scenario_hash
    return row


def columns(rows: list[dict], swept: list[str]) -> list[str]:
    cols = [*_FIRST, *swept, *_AFTER_SWEPT]
    seen = set(cols) | set(_LAST)
    for r in rows:
        for k in r:
            if k not in seen:
                seen.add(k)
                cols.append(k)
    return cols + list(_LAST)


def write_csv_atomic(path: Path, rows: list[dict], cols: list[str]) -> None:
    """The whole table into a temporary file beside `path`, then os.replace (as
    wormsim.runfolder.writer.write_json_atomic)."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in cols})
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(buf.getvalue())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def read_csv(path: Path) -> list[dict]:
    """Rows of an earlier sweep.csv with values as text ("" for none); [] when there is none."""
    if not path.is_file():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


# ----------------------------------------------------------------------------- progress


class SweepProgress:
    """Points done / total: a tqdm bar on a terminal; otherwise a log line per 10 % of the points (house style of
    wormsim.runfolder.progress; both off with WORMSIM_NO_PROGRESS)."""

    def __init__(self, name: str, total: int, done: int, enabled: bool | None = None, stream=None):
        self._stream = stream or sys.stderr
        off = bool(os.environ.get("WORMSIM_NO_PROGRESS"))
        tty = self._stream.isatty() if hasattr(self._stream, "isatty") else False
        bar = bool(enabled) if enabled is not None else (tty and not off)
        self._log = enabled is None and not tty and not off
        from tqdm import tqdm  # (here, not at the top: a worker imports this module for its tasks, never a bar)

        self._tqdm = tqdm
        self._bar = tqdm(
            total=total,
            initial=done,
            desc=f"sweep {name}",
            unit="point",
            disable=not bar,
            file=self._stream,
            leave=False,
        )
        self._name, self._total, self._done0, self._done, self._failed = name, total, done, done, 0
        self._t0 = time.perf_counter()
        self._next = 0.1

    def say(self, text: str) -> None:
        if self._log or not self._bar.disable:
            self._tqdm.write(text, file=self._stream)

    def point_done(self, failed: bool) -> None:
        self._done += 1
        self._failed += failed
        self._bar.update(1)
        frac = self._done / max(self._total, 1)
        if self._log and (frac >= self._next or self._done == self._total):
            wall = time.perf_counter() - self._t0
            ran = self._done - self._done0
            left = wall / ran * (self._total - self._done) if ran else 0.0
            print(
                f"sweep {self._name}: {self._done}/{self._total} points done ({self._failed} failed), "
                f"{wall / 60:.1f} min elapsed, about {left / 60:.1f} min left",
                file=self._stream,
                flush=True,
            )
            while self._next <= frac:
                self._next += 0.1

    def close(self) -> None:
        self._bar.close()


# ----------------------------------------------------------------------------- cluster


def machine_info() -> dict:
    def ver(pkg):
        try:
            return metadata.version(pkg)
        except metadata.PackageNotFoundError:
            return None

    return {
        "hostname": platform.node(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu_count": os.cpu_count(),
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "versions": {p: ver(p) for p in ("wormsim", "dask", "distributed", "numpy", "scipy", "mujoco")},
    }


def _free_threads(client) -> int:
    """Worker threads the scheduler knows now (at least 1; workers that join later are used from the next point)."""
    ws = client.scheduler_info().get("workers", {})
    return max(1, sum(w.get("nthreads", 0) for w in ws.values()))


# ----------------------------------------------------------------------------- the sweep


def _run_dir_name(p: Point) -> str:
    return f"p{p.index:04d}_{p.scenario_hash[:8]}"


def _json_doc(sweep: Sweep, rows: dict, timing: dict, machine: dict, cluster: dict | None, state: dict) -> dict:
    return {
        "name": sweep.spec.name,
        "sweep_file": str(sweep.path),
        "base": str(sweep.base_path),
        "sweep": sweep.raw,
        "swept_paths": sweep.swept_paths,
        **state,
        "machine": machine,
        "cluster": cluster,
        "points": [
            {
                "point": p.index,
                "values": p.values,
                "scenario_hash": p.scenario_hash,
                "status": rows[p.index]["status"] if p.index in rows else "not run",
                "timing": timing.get(p.index),
                "scenario": p.scenario.model_dump(mode="json"),
            }
            for p in sweep.points
        ],
    }


def run_sweep(
    sweep: Sweep,
    out_dir: str | Path,
    scheduler: str | None = None,
    workers: int | None = None,
    keep_runs: bool = False,
    progress: bool | None = None,
    started: ClusterStart | None = None,
) -> dict:
    """Run (or resume) the sweep into out_dir. Returns counts {points, ok, failed, resumed, ran}.
    started: a cluster started earlier (ClusterStart; scheduler and workers are then its); run_sweep closes it.
    KeyboardInterrupt propagates after sweep.csv / sweep.json hold the finished points."""
    if workers is not None and workers < 1:
        if started is not None:
            started.close()
        raise ScenarioError(f"--workers {workers}: allowed an integer >= 1")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / CSV_NAME
    swept = sweep.swept_paths
    earlier = read_csv(csv_path)
    rows, todo = _resume(sweep, earlier)
    resumed = len(rows)
    machine = machine_info()
    state = {
        "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "finished": None,
        "interrupted": False,
        "resumed_points": resumed,
        "keep_runs": keep_runs,
    }
    timing: dict[int, dict] = {}
    bar = SweepProgress(sweep.spec.name, len(sweep.points), resumed, enabled=progress)
    dropped = len({r.get("scenario_hash") for r in earlier} - {p.scenario_hash for p in sweep.points})
    if dropped:
        bar.say(
            f"sweep {sweep.spec.name}: {dropped} rows of {csv_path} belong to points no longer in this sweep "
            f"and are left out of the new table"
        )

    def flush_csv():
        ordered = [rows[i] for i in sorted(rows)]
        write_csv_atomic(csv_path, ordered, columns(ordered, swept))

    flush_csv()
    client = cluster = cluster_info = None
    interrupted = False
    t_sweep = time.perf_counter()
    try:
        if todo:
            if started is None:
                started = ClusterStart(scheduler, workers, warm=any(p.scenario.model == "contact3d" for p in todo))
            client, cluster, cluster_info = started.get()
            started = None
            if any(p.scenario.model == "contact3d" for p in todo):
                warm_workers(client, cluster_info)
            bar.say(
                f"sweep {sweep.spec.name}: {len(sweep.points)} points, {resumed} done earlier, {len(todo)} to run "
                f"on {cluster_info['workers']} workers ({cluster_info['kind']} {cluster_info['scheduler']})"
            )
            write_json_atomic(out / JSON_NAME, _json_doc(sweep, rows, timing, machine, cluster_info, state))

            def on_results(ps: list[Point], results: list[dict], t_submit: float, received: float) -> None:
                for p, res in zip(ps, results):
                    summary = res["summary"]
                    if keep_runs and res["files"]:
                        _write_run_dir(out / RUNS_DIR / _run_dir_name(p), res["files"], summary)
                    rows[p.index] = row_of(p, summary)
                    timing[p.index] = {
                        **(res["timing"] or {}),
                        "submitted": t_submit,
                        "received": received,
                        "result_bytes": sum(len(b) for b in res["files"].values()),
                    }
                    bar.point_done(summary.get("status") != "ok")
                flush_csv()

            # on a cluster given by address the figure's imports wait until the first points are out (plot_imports)
            _dispatch(client, todo, keep_runs, cluster_info, on_results, plot_imports if cluster is None else None)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        bar.close()
        if started is not None:  # (no point to run, or an error before the cluster was taken)
            started.close()
        state.update(
            finished=time.strftime("%Y-%m-%dT%H:%M:%S%z"), interrupted=interrupted, wall_s=time.perf_counter() - t_sweep
        )
        write_json_atomic(out / JSON_NAME, _json_doc(sweep, rows, timing, machine, cluster_info, state))
        _close_and_plot(client, cluster, sweep, [rows[i] for i in sorted(rows)], None if interrupted else out)
    if interrupted:
        raise KeyboardInterrupt
    n_ok = sum(1 for r in rows.values() if r.get("status") == "ok")
    return {"points": len(sweep.points), "ok": n_ok, "failed": len(rows) - n_ok, "resumed": resumed,
            "ran": len(todo), "cluster": cluster_info}  # fmt: skip


def _close_and_plot(client, cluster, sweep: Sweep, ordered: list[dict], out: Path | None) -> None:
    """The results are safe (sweep.csv and sweep.json final): the cluster closes in a thread while sweep.png is drawn
    into out (None: not drawn, an interrupted sweep). A figure that fails raises, with no sweep.png left in out."""
    import threading

    from wormsim.sweep import plot  # (before the closing thread: no two threads import at once, cluster.plot_imports)

    closing = threading.Thread(target=close_cluster, args=(client, cluster), name="wormsim-cluster-close", daemon=True)
    closing.start()
    try:
        if out is not None:
            try:
                plot.write_sweep_png(ordered, sweep.swept_paths, sweep.spec.plot, out / PNG_NAME, title=sweep.spec.name)
            except BaseException:  # the tables stay; an earlier sweep.png would look like theirs
                (out / PNG_NAME).unlink(missing_ok=True)
                raise
    finally:
        closing.join()


def _resume(sweep: Sweep, earlier: list[dict]) -> tuple[dict[int, dict], list[Point]]:
    """(rows kept from an earlier sweep.csv, by point index; the points still to run): a point whose scenario hash
    has an ok row there is not run again."""
    ok_rows = {r.get("scenario_hash"): r for r in earlier if r.get("status") == "ok"}
    rows: dict[int, dict] = {}
    todo: list[Point] = []
    for p in sweep.points:
        old = ok_rows.get(p.scenario_hash)
        if old is not None:
            kept = {k: v for k, v in old.items() if "." not in k}  # dotted names: swept paths of that sweep
            rows[p.index] = {**kept, "point": p.index, **p.values}
        else:
            todo.append(p)
    return rows, todo


def _dispatch(client, todo: list[Point], keep_runs: bool, cluster_info: dict, on_results, after_submit=None) -> None:
    """Run the points of todo on the cluster in chunks (task_sizes; cluster_info gets points_per_task, the largest);
    each finished chunk goes to on_results(points, results, submitted, received), a lost worker's chunk as failed
    results. Only as many points in flight as the cluster has threads: a point waits on the scheduler, not in a
    worker's queue, so a worker that dies (segfault, OOM killer) fails the point it ran and no other. after_submit
    (if given) runs once, after the first tasks are submitted."""
    from distributed import as_completed

    futures = {}
    queue = list(todo)
    threads = _free_threads(client)
    sizes = task_sizes(len(todo), threads)
    cluster_info["points_per_task"] = max(sizes, default=1)

    def submit_next():
        n = sizes.pop(0)
        ps = queue[:n]
        del queue[:n]
        scs = [p.scenario.model_dump(mode="json") for p in ps]
        key = f"wormsim-point-{ps[0].index}-{ps[0].scenario_hash}"
        if n == 1:
            fut = client.submit(run_point, scs[0], keep_runs, pure=False, key=key)
        else:
            fut = client.submit(run_points, scs, keep_runs, pure=False, key=f"{key}-{len(ps)}")
        futures[fut] = (ps, time.time())
        return fut

    pending = as_completed([submit_next() for _ in range(min(len(sizes), threads))])
    if after_submit is not None:
        after_submit()
    for fut in pending:
        if queue:
            pending.add(submit_next())
        ps, t_submit = futures[fut]
        try:
            out_ = fut.result()
            results = [out_] if len(ps) == 1 else out_
        except Exception as exc:  # (the worker died or the task could not run)
            results = [
                {
                    "summary": {
                        "status": "failed",
                        "wall_time_s": None,
                        "model": p.scenario.model,
                        "message": f"worker lost: {exc.__class__.__name__}: {exc}",
                    },
                    "files": {},
                    "timing": None,
                }
                for p in ps
            ]
        on_results(ps, results, t_submit, time.time())


def _write_run_dir(path: Path, files: dict[str, bytes], summary: dict) -> None:
    rd = ResultDir(path)
    for name, data in files.items():
        if name != "summary.json":
            rd.path(name).write_bytes(data)
    (rd.commit if summary.get("status") == "ok" else rd.fail)(summary)
