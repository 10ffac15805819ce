"""`wormsim sweep` with several points per task (wormsim.sweep.runner.chunk_size): every point a row of its own with
its own timing, the same rows as one point per task; the cluster started while the points are validated (an invalid
point still exits 2); workers forked warm; sweep.png drawn after the results are final; the command line's exit."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from wormsim import cli
from wormsim.sweep import load_sweep, run_sweep
from wormsim.sweep.runner import MAX_CHUNK, chunk_size, task_sizes

ROOT = Path(__file__).resolve().parents[2]
SWEEP = """name: chunks
base: {base}
set: {{model: torsional, simulation.duration_s: 0.01}}
grid:
  load.torque_nm: {{linspace: [4, 12, {n}]}}
"""


@pytest.fixture(autouse=True)
def _quiet(monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    monkeypatch.setenv("WORMSIM_NO_PROGRESS", "1")


def test_chunk_size():
    assert chunk_size(3, 2) == 1 and chunk_size(15, 2) == 1  # fewer than 8 points per thread: one per task
    assert chunk_size(16, 2) == 2 and chunk_size(16, 1) == 4 and chunk_size(1000, 4) == MAX_CHUNK
    assert chunk_size(16, 16) == 1


def test_task_sizes_end_in_single_points():
    assert task_sizes(16, 2) == [2] * 5 + [1] * 6  # the workers' last tasks are single points: no wait at the end
    assert task_sizes(8, 1) == [2, 2, 2, 1, 1] and task_sizes(15, 2) == [1] * 15 and task_sizes(0, 2) == []
    for n, threads in [(16, 1), (100, 4), (1000, 2), (37, 3)]:
        sizes = task_sizes(n, threads)
        assert sum(sizes) == n and max(sizes) == chunk_size(n, threads)
        assert sizes == sorted(sizes, reverse=True) and sizes[-2 * threads :] == [1] * (2 * threads)


@pytest.mark.long
def test_points_in_chunks_are_rows_of_their_own(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", n=8))
    res = run_sweep(load_sweep(f), tmp_path / "o", workers=1, progress=False)
    assert res["ok"] == 8 and res["cluster"]["points_per_task"] == 2
    with (tmp_path / "o" / "sweep.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["point"]) for r in rows] == list(range(8)) and {r["status"] for r in rows} == {"ok"}
    # each row is its own point's: the mean tangential force rises with the load torque, point by point
    forces = [float(r["tangential_force_mean_n"]) for r in rows]
    assert all(b > a for a, b in zip(forces, forces[1:])), forces
    doc = json.loads((tmp_path / "o" / "sweep.json").read_text())
    tim = [p["timing"] for p in doc["points"]]
    assert all(t["end"] >= t["start"] for t in tim)
    assert len({t["submitted"] for t in tim}) == 5  # tasks of 2, 2, 2, 1, 1 points (task_sizes)
    assert all("compile_s" in t and "jit_misses" in t for t in tim)


@pytest.mark.long
def test_an_invalid_point_exits_2_with_the_cluster_started(tmp_path, capsys):
    f = tmp_path / "s.yaml"
    f.write_text(SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", n=2) + "  gear.wheel_teeth: [30, 5]\n")
    code = cli.main(["sweep", str(f), "--out", str(tmp_path / "o"), "--workers", "1"])
    assert code == 2 and "gear.wheel_teeth = 5" in capsys.readouterr().err


def test_local_workers_start_warm_from_the_fork_server(tmp_path):
    """A contact3d sweep's local workers are forked from a fork server that loaded the compiled kernels once
    (wormsim.sweep.preload_warm): each point finds them loaded before it starts, on every worker; the warm-up plugin
    came with the workers (wormsim.sweep.cluster.open_client), not registered after they started."""
    f = tmp_path / "s.yaml"
    f.write_text(
        "name: warm\nbase: {base}\nset: {{model: contact3d, simulation.duration_s: 0.004}}\n"
        "grid:\n  drive.speed_rpm: [1000, 1500]\n".format(base=ROOT / "scenarios" / "screw_jack.yaml")
    )
    wormsim = Path(sys.executable).parent / "wormsim"
    cp = subprocess.run(
        [str(wormsim), "sweep", str(f), "--out", str(tmp_path / "o"), "--workers", "2", "--no-progress"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert cp.returncode == 0, cp.stderr
    doc = json.loads((tmp_path / "o" / "sweep.json").read_text())
    timing = [p["timing"] for p in doc["points"]]
    assert len(timing) == 2, timing
    warmed_by = {t["warmed_by_pid"] for t in timing}
    assert len(warmed_by) == 1 and None not in warmed_by and not warmed_by & {t["pid"] for t in timing}, timing
    # the workers got the warm-up plugin when they were made: the client registered none before the first point
    assert doc["cluster"]["warm_at_start"] is True and doc["cluster"]["warm_s"] == 0.0, doc["cluster"]
    # each point's thread CPU seconds: spent, and within its wall time (a thread runs on one core at a time)
    assert all(0.0 < t["thread_cpu_s"] <= t["end"] - t["start"] + 0.01 for t in timing), timing


def test_warm_worker_runs_once_per_process(monkeypatch):
    """wormsim.sweep.warm.warm_worker: ensure_warm and the short run once; later calls (a worker forked from a warm
    fork server, the plugin after the preload) skip; a failure is reported, not raised, and leaves it to retry."""
    import os

    from wormsim.contact3d import runner as c3d_runner
    from wormsim.runtime import jit_cache
    from wormsim.sweep import warm

    calls = []
    monkeypatch.setattr(warm, "_warm_pid", None)
    monkeypatch.setattr(jit_cache, "ensure_warm", lambda runs: calls.append("ensure") or False)
    monkeypatch.setattr(c3d_runner, "_warm_friction_check", lambda: calls.append("friction"))

    def fails(runs, steps=None):
        raise RuntimeError("no cache")

    monkeypatch.setattr(c3d_runner, "warm_runs", fails)
    assert warm.warm_worker()["error"] == "RuntimeError: no cache" and warm.warm_pid() is None
    monkeypatch.setattr(c3d_runner, "warm_runs", lambda runs, steps=None: calls.append(("run", len(runs), steps)))
    assert warm.warm_worker() == {"compiled": False, "error": None, "skipped": False}
    assert warm.warm_pid() == os.getpid()
    assert warm.warm_worker()["skipped"] is True
    # one run of the machine's warm-up, long enough to sample, and the friction check
    assert calls == ["ensure", "ensure", ("run", 1, warm.SAMPLED_STEPS), "friction"]


def test_the_figure_comes_after_the_results_and_a_failing_one_keeps_them(tmp_path, monkeypatch):
    """sweep.png is drawn once sweep.csv holds every row and sweep.json is final; a figure that fails leaves both as
    they are and no sweep.png beside them (not an earlier one that looks current)."""
    from wormsim.sweep import plot

    f = tmp_path / "s.yaml"
    f.write_text(SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", n=2).replace("0.01", "0.004"))
    out = tmp_path / "o"
    seen = []
    draw = plot.write_sweep_png

    def recorded(rows, *args, **kwargs):
        with (out / "sweep.csv").open(newline="") as fh:
            on_disk = list(csv.DictReader(fh))
        doc = json.loads((out / "sweep.json").read_text())
        seen.append(([r["status"] for r in on_disk], doc["finished"] is not None, doc["interrupted"]))
        draw(rows, *args, **kwargs)

    monkeypatch.setattr(plot, "write_sweep_png", recorded)
    assert run_sweep(load_sweep(f), out, workers=1, progress=False)["ok"] == 2
    assert seen == [(["ok", "ok"], True, False)] and (out / "sweep.png").is_file()
    csv_text, doc = (out / "sweep.csv").read_text(), json.loads((out / "sweep.json").read_text())

    def fails(*args, **kwargs):
        raise RuntimeError("no figure")

    monkeypatch.setattr(plot, "write_sweep_png", fails)
    with pytest.raises(RuntimeError, match="no figure"):
        run_sweep(load_sweep(f), out, progress=False)  # resumed: both points done, no cluster
    assert (out / "sweep.csv").read_text() == csv_text
    again = json.loads((out / "sweep.json").read_text())
    assert [p["status"] for p in again["points"]] == ["ok", "ok"] and again["resumed_points"] == 2
    assert again["finished"] is not None and not again["interrupted"] and doc["finished"] is not None
    assert not (out / "sweep.png").exists()


def test_the_command_line_ends_the_process_after_its_output(tmp_path):
    """wormsim.cli.entry.exit_now: the atexit handlers run and stdout is flushed, then the process ends with the
    command's code (no finalization)."""
    code = (
        "import atexit, sys\n"
        "from wormsim.cli.entry import exit_now\n"
        "atexit.register(lambda: print('atexit ran', file=sys.stderr))\n"
        "print('written', end='')\n"
        "exit_now(3)\n"
        "print('not reached')\n"
    )
    cp = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert (cp.returncode, cp.stdout, cp.stderr.strip()) == (3, "written", "atexit ran")


def test_main_from_the_command_line_exits_a_sweep_itself(tmp_path, monkeypatch):
    """main() with no argv (the console script) ends a sweep with exit_now; main(argv) returns the code."""
    from wormsim.cli import entry

    f = tmp_path / "s.yaml"
    f.write_text(SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", n=1).replace("0.01", "0.004"))
    out = tmp_path / "o"
    assert entry.main(["sweep", str(f), "--out", str(out), "--workers", "1"]) == 0
    ended = []
    monkeypatch.setattr(entry, "exit_now", ended.append)
    monkeypatch.setattr(sys, "argv", ["wormsim", "sweep", str(f), "--out", str(out)])
    assert entry.main() == 0 and ended == [0]  # resumed: the point is done, no cluster
    monkeypatch.setattr(sys, "argv", ["wormsim", "schema", "--out", str(tmp_path / "schema.json")])
    assert entry.main() == 0 and ended == [0]  # other commands return
