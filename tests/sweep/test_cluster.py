"""wormsim.sweep.cluster: which fork server a sweep file asks for (read before wormsim.sweep.spec is imported, the same
answer as load_sweep's), and `wormsim sweep` starting it before its own imports and validation; an invalid sweep
file stops it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from wormsim.sweep import load_sweep
from wormsim.sweep.cluster import (
    LOCAL_DASK_CONFIG,
    close_cluster,
    may_run_contact3d,
    open_client,
    peek_contact3d,
    start_fork_server,
    stop_fork_server,
)

ROOT = Path(__file__).resolve().parents[2]
SCREW_JACK = ROOT / "scenarios" / "screw_jack.yaml"  # model: contact3d

SWEEPS = {
    "base_contact3d": "grid: {drive.speed_rpm: [1000, 1200]}",
    "set_torsional": "set: {model: torsional}\ngrid: {drive.speed_rpm: [1000, 1200]}",
    "grid_model": "set: {simulation.duration_s: 0.1}\ngrid: {model: [torsional, contact3d]}",
    "zip_model": "zip: {model: [wedge, torsional], drive.speed_rpm: [1000, 1200]}",
    "torsional_random": (
        "set: {model: torsional}\nrandom: {n: 2, seed: 1, vary: {gear.backlash_mm: {uniform: [0.05, 0.1]}}}"
    ),
}


@pytest.mark.parametrize("case", sorted(SWEEPS))
def test_peek_agrees_with_load_sweep(case, tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(f"name: peek\nbase: {SCREW_JACK}\n{SWEEPS[case]}\n")
    seen: list[bool] = []
    load_sweep(f, on_parsed=seen.append)
    assert seen == [peek_contact3d(f)]
    assert seen[0] is (case not in ("set_torsional", "torsional_random"))


def test_may_run_contact3d():
    assert may_run_contact3d(None, []) and may_run_contact3d("contact3d", ["drive.speed_rpm"])
    assert not may_run_contact3d("torsional", ["drive.speed_rpm"]) and may_run_contact3d("wedge", ["model"])


def test_peek_of_what_it_cannot_read_is_none(tmp_path):
    """None (load_sweep then names the problem, exit 2): no file, not YAML, no base, a base that is not there."""
    assert peek_contact3d(tmp_path / "nope.yaml") is None
    bad = {
        "yaml": "name: x\nbase: [unclosed\n",
        "no_base": "name: x\ngrid: {a: [1]}\n",
        "base_missing": "base: b.yaml\n",
    }
    for name, text in bad.items():
        (tmp_path / f"{name}.yaml").write_text(text)
        assert peek_contact3d(tmp_path / f"{name}.yaml") is None, name


def test_peek_does_not_expand_aliases(tmp_path):
    """The peek composes nodes (yaml.compose): a file of nested aliases (10^9 values expanded) is read as it is
    written; load_sweep then refuses it (wormsim.scenario's YAML limits)."""
    lines = ["name: bomb", f"base: {SCREW_JACK}", "a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 9)]
    lines += ["grid: {drive.speed_rpm: *a8}"]
    (tmp_path / "s.yaml").write_text("\n".join(lines) + "\n")
    assert peek_contact3d(tmp_path / "s.yaml") is True


def test_stop_fork_server_ends_its_process():
    from multiprocessing import forkserver

    start_fork_server(False)
    pid = forkserver._forkserver._forkserver_pid
    assert pid is not None
    stop_fork_server()
    assert forkserver._forkserver._forkserver_pid is None
    with pytest.raises(ProcessLookupError):  # reaped: no such process
        os.kill(pid, 0)


def _worker_settings() -> dict:
    import dask

    return {
        "config": {k: dask.config.get(k) for k in LOCAL_DASK_CONFIG},
        "env": {k: os.environ.get(k) for k in ("OPENBLAS_THREAD_TIMEOUT", "MUJOCO_GL")},
    }


def test_local_workers_run_with_the_sweeps_dask_settings():
    """A local cluster's worker (forked from the fork server) has LOCAL_DASK_CONFIG (no profiler, slower monitors),
    OpenBLAS's threads that do not spin and MuJoCo without GL (wormsim.sweep.preload; a value the user set wins); the
    scheduler has no work stealing."""
    start_fork_server(False)
    client, cluster, info = open_client(None, 1)
    try:
        assert info["workers"] == 1
        (got,) = client.run(_worker_settings).values()
        stealing = client.run_on_scheduler(lambda dask_scheduler: "stealing" in dask_scheduler.extensions)
    finally:
        close_cluster(client, cluster)
    assert got["config"] == LOCAL_DASK_CONFIG
    assert got["env"] == {
        "OPENBLAS_THREAD_TIMEOUT": os.environ.get("OPENBLAS_THREAD_TIMEOUT", "4"),
        "MUJOCO_GL": os.environ.get("MUJOCO_GL", "disable"),
    }
    assert stealing is False


# `wormsim sweep` with the cluster's start recorded instead of run: what had been imported when the fork server
# started, and whether the cluster started before the points' validation ended
_RECORD = """
import json, sys
import wormsim.sweep.cluster as c
events = []
loaded = lambda: [m for m in ("wormsim.sweep.spec", "numba", "pydantic", "distributed") if m in sys.modules]
c.start_fork_server = lambda warm: events.append(["fork server", warm, loaded()])
c.stop_fork_server = lambda: events.append(["stopped"])
class Started:
    used = False
    def __init__(self, scheduler, workers, warm=True):
        events.append(["cluster", warm])
    def close(self):
        events.append(["closed"])
c.ClusterStart = Started
from wormsim.cli import entry
code = entry.main(sys.argv[1:])
print(json.dumps({"code": code, "events": events}))
"""


def _record(args: list[str]) -> dict:
    cp = subprocess.run([sys.executable, "-c", _RECORD, *args], capture_output=True, text=True, timeout=300)
    assert cp.returncode == 0, cp.stderr
    return json.loads(cp.stdout.splitlines()[-1])


def test_cli_starts_the_fork_server_first_and_the_cluster_before_validation_ends(tmp_path):
    """The fork server starts before the client imports the sweep's modules (no numba, pydantic or dask yet); the
    cluster starts before the points are validated: a sweep whose last point is invalid exits 2 with the cluster
    started, then closed."""
    f = tmp_path / "s.yaml"
    f.write_text(f"name: late\nbase: {SCREW_JACK}\nset: {{model: torsional}}\ngrid: {{gear.wheel_teeth: [30, 5]}}\n")
    rec = _record(["sweep", str(f), "--out", str(tmp_path / "o"), "--workers", "1"])
    assert rec == {"code": 2, "events": [["fork server", False, []], ["cluster", False], ["closed"]]}


def test_cli_stops_the_fork_server_of_an_invalid_sweep_file(tmp_path):
    """A sweep file that fails its own checks (before the points are built) starts no cluster, and the fork server
    started for it is stopped rather than waited for."""
    f = tmp_path / "s.yaml"
    f.write_text(f"name: bad\nbase: {SCREW_JACK}\ngrid: {{drive.speed_rpm: {{linspace: [1, 2]}}}}\n")
    rec = _record(["sweep", str(f), "--out", str(tmp_path / "o")])
    assert rec == {"code": 2, "events": [["fork server", True, []], ["stopped"]]}


# a forked worker's state before its first task: the fork server's preload, then the task's bytes unpickled
_FIRST_TASK = """
import json, sys
import distributed.versions as v
import wormsim.sweep.preload  # noqa: F401
from distributed.protocol.pickle import loads
before = set(sys.modules)
loads(bytes.fromhex(sys.argv[1]))
print(json.dumps({"new": sorted(set(sys.modules) - before), "tqdm": "tqdm" in sys.modules,
                  "versions_cached": v._version_cached.cache_info().currsize}))
"""


def test_the_preload_holds_what_a_worker_needs_before_its_first_point():
    """After the fork server's preload (wormsim.sweep.preload) a worker unpickles its first task (run_point,
    run_points) without importing a module, never imports tqdm (the client's progress bar), and has the package
    versions it registers with cached (distributed.versions.get_versions: not run again in each forked worker)."""
    from distributed.protocol.pickle import dumps

    from wormsim.sweep.runner import run_point, run_points

    task = dumps((run_point, run_points, ({"name": "x"}, False)))
    cp = subprocess.run(
        [sys.executable, "-c", _FIRST_TASK, task.hex()], capture_output=True, text=True, timeout=300, cwd=ROOT
    )
    assert cp.returncode == 0, cp.stderr
    got = json.loads(cp.stdout.splitlines()[-1])
    assert got["new"] == [] and got["tqdm"] is False, got
    assert got["versions_cached"] > 0


@pytest.mark.parametrize("scheduler", [None, "tcp://127.0.0.1:1"])
def test_the_cluster_start_thread_imports_matplotlib_before_distributed(tmp_path, scheduler):
    """A local cluster's start thread imports matplotlib and distributed (cluster.plot_imports, then open_client): in
    a fresh interpreter it finds matplotlib.pyplot imported and distributed not yet when it opens the client, so no
    two threads import at once (importlib's _DeadlockError between pyparsing's `html` and tornado's `html.entities`,
    a command's exit 1). With a scheduler's address nothing waits for a fork server: the start thread connects
    without importing matplotlib (run_sweep imports it once the first points are out)."""
    import subprocess
    import sys

    code = (
        "import sys, threading\n"
        "from wormsim.sweep import cluster\n"
        "seen = {}\n"
        "def fake(scheduler, workers, warm=False):\n"
        "    seen.update(mpl='matplotlib.pyplot' in sys.modules, dist='distributed' in sys.modules,\n"
        "                thread=threading.current_thread().name)\n"
        "    return (None, None, {})\n"
        "cluster.open_client = fake\n"
        "cluster.start_fork_server = lambda warm: None\n"
        f"cluster.ClusterStart({scheduler!r}, 1, warm=False).get()\n"
        "print(seen['mpl'], seen['dist'], seen['thread'], 'matplotlib.pyplot' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert out.returncode == 0, out.stderr
    mpl = str(scheduler is None)
    assert out.stdout.split() == [mpl, "False", "wormsim-cluster-start", mpl], out.stdout
