"""`wormsim sweep` (INTERFACE.md, "Sweep file"): point expansion, validation (exit 2), a 2-worker LocalCluster, an
external `dask scheduler` / `dask worker` pair, a failing point, resume after Ctrl-C. Points are torsional
screw-jack runs of 0.12 s (about a second each)."""

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from wormsim import cli
from wormsim.sweep import load_sweep
from wormsim.sweep.spec import SweepFile, expand

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "tests" / "assets" / "sweep_torsional.yaml"
SCREW_JACK = ROOT / "scenarios" / "screw_jack.yaml"
BIN = Path(sys.executable).parent
# columns that hold wall-clock times: they differ between two runs of the same point
TIMING = ("wall_time_s", "solve_wall_s", "mesh_stiffness_wall_s")
# exit codes asserted: 0 ok, 2 invalid input, 3 simulation failed, 130 / 143 interrupted (docs/cli.md, INTERFACE.md)


@pytest.fixture(autouse=True)
def _no_external_scheduler(monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    monkeypatch.setenv("WORMSIM_NO_PROGRESS", "1")


def _rows(d: Path) -> list[dict]:
    with (d / "sweep.csv").open(newline="") as fh:
        return list(csv.DictReader(fh))


def _header(d: Path) -> list[str]:
    return (d / "sweep.csv").read_text().splitlines()[0].split(",")


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


# ----------------------------------------------------------------------------- the sweep file


def test_expand_grid_zip_random_in_order():
    spec = SweepFile.model_validate(
        {
            "name": "t",
            "base": "x.yaml",
            "grid": {"a.b": [1, 2], "c.d": {"linspace": [0.0, 1.0, 3]}},
            "zip": {"e.f": [10, 20], "g.h": [30, 40]},
            "random": {"n": 2, "seed": 7, "vary": {"i.j": {"uniform": [0.0, 1.0]}}},
        }
    )
    pts = expand(spec)
    # grid 2 x 3, zip 2 (side by side), random n 2: the product of the axes' lengths
    assert len(pts) == 2 * 3 * 2 * 2
    assert pts[0] == {"a.b": 1, "c.d": 0.0, "e.f": 10, "g.h": 30, "i.j": pts[0]["i.j"]}
    assert [p["c.d"] for p in pts[:12:4]] == [0.0, 0.5, 1.0]  # the last axes vary fastest
    assert {(p["e.f"], p["g.h"]) for p in pts} == {(10, 30), (20, 40)}  # zip: side by side, not crossed
    assert pts == expand(spec)  # the seed fixes the draws
    assert all(0.0 <= p["i.j"] <= 1.0 for p in pts)
    log = SweepFile.model_validate({"name": "t", "base": "x", "grid": {"a": {"logspace": [1.0e2, 1.0e4, 3]}}})
    # logspace [1e2, 1e4, 3] = 10^2, 10^3, 10^4 (numpy.logspace)
    assert [p["a"] for p in expand(log)] == pytest.approx([100.0, 1000.0, 10000.0])


def test_points_are_validated_and_hashed():
    sw = load_sweep(SWEEP)
    assert [p.values for p in sw.points] == [
        {"contact.stiffness_n_per_m": 2.0e8, "load.torque_nm": 12},
        {"contact.stiffness_n_per_m": 6.0e8, "load.torque_nm": 12},
        {"contact.stiffness_n_per_m": 4.39e8, "load.torque_nm": 30000},
    ]
    # the set: block of tests/assets/sweep_torsional.yaml (inputs echoed back)
    assert all(p.scenario.model == "torsional" and p.scenario.simulation.duration_s == 0.12 for p in sw.points)
    # zip value 2 of tests/assets/sweep_torsional.yaml
    assert sw.points[1].scenario.contact.stiffness_n_per_m == 6.0e8
    assert len({p.scenario_hash for p in sw.points}) == 3
    assert load_sweep(SWEEP).points[0].scenario_hash == sw.points[0].scenario_hash


@pytest.mark.parametrize("path", sorted((ROOT / "studies").glob("*.yaml")), ids=lambda p: p.stem)
def test_shipped_sweeps_validate(path):
    """Every study in studies/ expands into valid points (they run for minutes, so CI only validates them)."""
    sw = load_sweep(path)
    assert sw.spec.name == path.stem and len(sw.points) >= 3
    assert len({p.scenario_hash for p in sw.points}) == len(sw.points)


BAD = {
    "bad_point": (
        "set: {model: torsional}\ngrid: {gear.wheel_teeth: [24, 5]}",
        "point 1 (gear.wheel_teeth=5): gear.wheel_teeth = 5: Input should be greater than or equal to 10",
    ),
    "unknown_path": ("grid: {contact.stifness_n_per_m: [1.0e8]}", "unknown key 'contact.stifness_n_per_m'"),
    "not_a_block": ("grid: {gear.wheel_teeth.x: [1]}", "'gear.wheel_teeth' is not a block"),
    "linspace_short": (
        "grid: {drive.speed_rpm: {linspace: [1, 2]}}",
        "grid.drive.speed_rpm.linspace = [1, 2]: expected [a, b, n]",
    ),
    "logspace_zero": ("grid: {drive.speed_rpm: {logspace: [0, 2, 3]}}", "must be > 0"),
    "scalar_axis": ("grid: {drive.speed_rpm: 5}", "grid.drive.speed_rpm = 5: expected a list of values"),
    "zip_lengths": ("zip: {drive.speed_rpm: [1, 2], load.torque_nm: [1]}", "zip: every path needs the same number"),
    "swept_and_set": ("set: {drive.speed_rpm: 3}\ngrid: {drive.speed_rpm: [1]}", "a path may be swept once"),
    "no_axes": ("set: {drive.speed_rpm: 3}", "at least one of grid / zip / random"),
    "bad_distribution": (
        "random: {n: 3, vary: {drive.speed_rpm: {gauss: [1, 2]}}}",
        "random.vary.drive.speed_rpm = {'gauss': [1, 2]}: expected {uniform",
    ),
    "unknown_top_key": ("grids: {drive.speed_rpm: [1]}", "unknown key 'grids'"),
    "missing_base": ("grid: {drive.speed_rpm: [1]}", "base = nope.yaml: no such scenario file"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_invalid_sweep_file_exits_2_naming_the_field(case, tmp_path, capsys):
    body, expected = BAD[case]
    base = "nope.yaml" if case == "missing_base" else str(SCREW_JACK)
    f = _write(tmp_path / "s.yaml", f"name: bad\nbase: {base}\n{body}\n")
    out = tmp_path / "out"
    assert cli.main(["sweep", str(f), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err
    assert not out.exists()  # nothing ran


def test_a_scenario_given_as_sweep_file_is_named_as_such(tmp_path, capsys):
    f = _write(tmp_path / "gear.yaml", SCREW_JACK.read_text())
    assert cli.main(["sweep", str(f), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "gear.yaml: a scenario, not a sweep file" in err and "wormsim run gear.yaml" in err
    assert err.count("\n") == 1 and "did you mean" not in err


# ----------------------------------------------------------------------------- running


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "local"
    env_before = os.environ.pop("DASK_SCHEDULER_ADDRESS", None)
    try:
        code = cli.main(["sweep", str(SWEEP), "--out", str(out), "--workers", "2", "--no-progress"])
    finally:
        if env_before is not None:
            os.environ["DASK_SCHEDULER_ADDRESS"] = env_before
    return code, out


def test_local_cluster_two_workers_with_a_failing_point(local_run):
    code, out = local_run
    assert code == 0  # the sweep ran; the failed point is a row
    head = _header(out)
    assert head[:5] == ["point", "contact.stiffness_n_per_m", "load.torque_nm", "status", "message"]
    assert head[-2:] == ["wall_time_s", "scenario_hash"]
    rows = _rows(out)
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    assert "teeth would skip" in rows[2]["message"]
    for r in rows[:2]:  # under a fixed load torque the mean tangential force is T2 / r2 = 12 N m / 30 mm
        assert float(r["tangential_force_mean_n"]) == pytest.approx(400.0, rel=1e-4)
        assert float(r["contact.stiffness_n_per_m"]) in (2.0e8, 6.0e8)
    doc = json.loads((out / "sweep.json").read_text())
    # the --workers 2 of local_run (input echoed back)
    assert doc["cluster"]["kind"].startswith("LocalCluster") and doc["cluster"]["workers"] == 2
    assert doc["cluster"]["threads"] == 2
    assert [p["status"] for p in doc["points"]] == ["ok", "ok", "failed"]
    # zip value 2 of tests/assets/sweep_torsional.yaml
    assert doc["points"][1]["scenario"]["contact"]["stiffness_n_per_m"] == 6.0e8
    assert doc["sweep"]["name"] == "test_torsional" and doc["machine"]["cpu_count"] >= 1
    assert len({p["timing"]["worker"] for p in doc["points"]}) == 2  # both workers took points
    # 10 kB: a bound for a rendered figure rather than an empty file, not a measured value
    assert (out / "sweep.png").stat().st_size > 10_000
    assert not (out / "runs").exists()  # per-point folders only with --keep-runs


def _torsional_sweep(tmp_path, capsys, name: str, duration_s: float, grid: str):
    """`wormsim sweep` on one worker of the screw jack at torsional over `grid`: (exit code, stderr, the table's rows)."""
    f = _write(
        tmp_path / f"{name}.yaml",
        f"name: {name}\nbase: {SCREW_JACK}\nset: {{model: torsional, simulation.duration_s: {duration_s}}}\n"
        f"grid: {{{grid}}}\n",
    )
    out = tmp_path / "out"
    rc = cli.main(["sweep", str(f), "--out", str(out), "--workers", "1", "--no-progress"])
    return rc, capsys.readouterr().err, _rows(out)


def test_a_sweep_whose_every_point_fails_exits_3_with_the_first_message(tmp_path, capsys):
    rc, err, rows = _torsional_sweep(tmp_path, capsys, "all_fail", 0.12, "load.torque_nm: [30000, 40000]")
    assert rc == 3
    assert "every point of sweep all_fail failed" in err and "teeth would skip" in err
    assert [r["status"] for r in rows] == ["failed", "failed"]  # the table is still written


def test_a_sweep_whose_every_point_is_invalid_input_exits_2_naming_the_field(tmp_path, capsys):
    """Every point refused by the scenario checks (a face width past the root torus's limit on every point; the random
    gears' test found 21 of 66 such sweeps exiting 3, "simulation failed"): the input is at fault, exit 2 with the
    first point's field."""
    rc, err, rows = _torsional_sweep(tmp_path, capsys, "all_invalid", 0.05, "gear.face_width_mm: [200, 300]")
    assert rc == 2
    assert "error: every point of sweep all_invalid is invalid input (the first: gear.face_width_mm" in err, err
    assert [r["status"] for r in rows] == ["failed", "failed"]


def _start(args: list[str], log: Path) -> subprocess.Popen:
    fh = log.open("w")
    return subprocess.Popen(args, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True)


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=15)


def test_external_scheduler_gives_the_same_table(local_run, tmp_path, capsys):
    _, local = local_run
    sched_file = tmp_path / "scheduler.json"
    sched = _start(
        [
            str(BIN / "dask"),
            "scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(sched_file),
        ],
        tmp_path / "scheduler.log",
    )
    worker = None
    try:
        t0 = time.monotonic()
        while not sched_file.exists() and time.monotonic() - t0 < 60 and sched.poll() is None:
            time.sleep(0.2)
        assert sched_file.exists(), (tmp_path / "scheduler.log").read_text()
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        worker = _start(
            [
                str(BIN / "dask"),
                "worker",
                address,
                "--nthreads",
                "1",
                "--nworkers",
                "1",
                "--no-dashboard",
                "--host",
                "127.0.0.1",
            ],
            tmp_path / "worker.log",
        )
        out = tmp_path / "remote"
        code = cli.main(
            ["sweep", str(SWEEP), "--out", str(out), "--scheduler", address, "--keep-runs", "--no-progress"]
        )
        assert code == 0, capsys.readouterr().err
    finally:
        for p in (worker, sched):
            if p is not None:
                _stop(p)
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["cluster"]["kind"] == "existing scheduler" and doc["cluster"]["scheduler"] == address
    assert (out / "sweep.png").stat().st_size > 10_000  # (matplotlib imported while the points ran)
    a, b = _rows(local), _rows(out)
    assert _header(local) == _header(out)
    for ra, rb in zip(a, b, strict=True):
        assert {k: v for k, v in ra.items() if k not in TIMING} == {k: v for k, v in rb.items() if k not in TIMING}
    # --keep-runs: the result files came back through the client (the worker wrote into its own temp dir)
    runs = sorted((out / "runs").iterdir())
    assert len(runs) == 3
    ok = json.loads((runs[0] / "summary.json").read_text())
    assert ok["status"] == "ok" and (runs[0] / "report.png").is_file() and (runs[0] / "timeseries.npz").is_file()
    failed = json.loads((runs[2] / "summary.json").read_text())
    assert failed["status"] == "failed" and not (runs[2] / "report.png").exists()


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_resume_after_ctrl_c_skips_finished_points(tmp_path, capsys):
    sweep = _write(
        tmp_path / "resume.yaml",
        (
            f"name: resume\nbase: {SCREW_JACK}\nset: {{model: torsional, simulation.duration_s: 0.12}}\n"
            "grid: {drive.speed_rpm: {linspace: [1000, 1500, 6]}}\n"
        ),
    )
    out = tmp_path / "out"
    env = {**os.environ, "WORMSIM_NO_PROGRESS": "1"}
    proc = subprocess.Popen(
        [str(BIN / "wormsim"), "sweep", str(sweep), "--out", str(out), "--workers", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        preexec_fn=_default_sigint,  # as on a terminal (a background job's child inherits SIGINT ignored)
    )
    try:
        t0 = time.monotonic()
        while time.monotonic() - t0 < 120 and proc.poll() is None:
            if (out / "sweep.csv").exists() and len(_rows(out)) >= 2:
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)  # Ctrl-C
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    first = _rows(out)
    assert 2 <= len(first) < 6, "the sweep should have been interrupted midway"
    assert all(r["status"] == "ok" for r in first)
    assert json.loads((out / "sweep.json").read_text())["interrupted"] is True
    assert not [f for f in out.iterdir() if f.name.startswith(".")]  # no temporary files left

    assert cli.main(["sweep", str(sweep), "--out", str(out), "--workers", "2", "--no-progress"]) == 0
    assert f"({len(first)} done earlier, {6 - len(first)} run now)" in capsys.readouterr().out
    rows = _rows(out)
    assert [int(r["point"]) for r in rows] == list(range(6)) and all(r["status"] == "ok" for r in rows)
    for r in first:  # the finished points were not run again
        assert rows[int(r["point"])]["wall_time_s"] == r["wall_time_s"]
    # linspace [1000, 1500, 6] of the sweep above (numpy.linspace)
    assert [float(r["drive.speed_rpm"]) for r in rows] == pytest.approx([1000, 1100, 1200, 1300, 1400, 1500])
    # a third run has nothing to do and starts no cluster
    assert cli.main(["sweep", str(sweep), "--out", str(out), "--no-progress"]) == 0
    assert "(6 done earlier, 0 run now)" in capsys.readouterr().out


def test_a_lost_worker_is_a_failed_row(tmp_path, monkeypatch):
    """A point whose worker process dies (os._exit, as a segfault or the OOM killer would) is a failed row; the
    others finish. allowed-failures 0: the scheduler gives the task up after the first lost worker."""
    import dask

    from wormsim.sweep import runner

    real = runner.run_point

    def dying(sc, keep):  # a local function is pickled by value (cloudpickle): the worker runs this one
        return os._exit(1) if sc["load"]["torque_nm"] > 1000 else real(sc, keep)

    monkeypatch.setattr(runner, "run_point", dying)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        sw = load_sweep(SWEEP)
        counts = runner.run_sweep(sw, tmp_path / "out", workers=2, progress=False)
    assert counts["ok"] == 2 and counts["failed"] == 1
    rows = _rows(tmp_path / "out")
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    assert rows[2]["message"].startswith("worker lost: KilledWorker")


def test_sweep_png_plain_tick_labels(tmp_path, monkeypatch):
    """sweep.png of an output constant to 1e-9 (a torsional efficiency against mu-independent inputs): no offset
    text on any axis ("1e-7+8.04e-1" made a constant look like a slope) and a y range of at least 1 % of the value,
    so the line draws flat."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wormsim.sweep.plot import write_sweep_png

    figs = []
    monkeypatch.setattr(plt, "close", figs.append)  # keep the figure to inspect it
    rows = [
        {"status": "ok", "load.torque_nm": 1000.0 + i, "efficiency": 0.8040233 + 1e-9 * i, "ratio": 15.0}
        for i in range(5)
    ]
    write_sweep_png(rows, ["load.torque_nm"], None, tmp_path / "sweep.png")
    assert (tmp_path / "sweep.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (fig,) = figs
    fig.canvas.draw()
    axes = [a for a in fig.axes if a.get_visible()]
    assert {a.get_ylabel() for a in axes} == {"efficiency", "ratio"}
    for a in axes:
        assert a.yaxis.get_offset_text().get_text() == "" and a.xaxis.get_offset_text().get_text() == ""
        lo, hi = a.get_ylim()
        # MIN_REL_SPAN = 0.01 of wormsim/sweep/plot.py (less 1e-4 for rounding)
        assert hi - lo >= 0.0099 * abs(0.5 * (lo + hi))
