"""CLI exit codes and atomic result writing (INTERFACE.md: 0 ok, 2 invalid input, 3 simulation failed)."""

import json
import subprocess
import sys
import types
from pathlib import Path

import numpy as np

from tests.conftest import ROOT
from wormsim import cli, run
from wormsim.exceptions import SimulationError
from wormsim.results.result import Result
from wormsim.scenario import load_scenario

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"
# exit codes asserted: 0 ok, 2 invalid input, 3 simulation failed, 130 / 143 interrupted (docs/cli.md, INTERFACE.md)


def test_check_prints_defaults(capsys):
    assert cli.main(["check", str(MINIMAL)]) == 0
    out = capsys.readouterr().out
    assert "profile: ZI" in out and "duration_s" in out


def test_invalid_input_exits_2_with_one_line_per_problem(capsys):
    code = cli.main(["check", str(MINIMAL), "--set", "gear.wheel_teeth=5", "--set", "gear.hand=up"])
    err = capsys.readouterr().err
    assert code == 2
    assert "gear.wheel_teeth = 5: Input should be greater than or equal to 10" in err
    assert 'gear.hand = "up"' in err and "'right' or 'left'" in err
    assert "Traceback" not in err


def test_run_invalid_input_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "o"
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--set", "simulation.duration_s=-1"]) == 2
    assert "simulation.duration_s = -1" in capsys.readouterr().err
    assert not out.exists()


def test_schema_command_writes_json(tmp_path):
    f = tmp_path / "schema.json"
    assert cli.main(["schema", "--out", str(f)]) == 0
    assert json.loads(f.read_text())["title"] == "Scenario"


def test_console_script_is_installed():
    exe = Path(sys.executable).with_name("wormsim")
    r = subprocess.run([str(exe), "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "run" in r.stdout and "bench" in r.stdout


# --- atomic writes, with a stand-in fidelity level so the runner is tested on its own --------------


def _fake_level(fail: bool):
    def simulate(scenario, progress=None):
        if fail:
            raise SimulationError("timestep 1e-3 s exceeds the contact's stable limit ~2e-4 s")
        t = np.linspace(0, 1, 11)
        return Result(model="contact3d", summary={"ratio": 30.0}, series={"t_s": t, "x": t}, steps=10, sim_time_s=1.0)

    def write_report(res, path):
        Path(path).write_bytes(b"png")

    def write_recording(res, path):
        Path(path).write_bytes(b"rrd")

    return types.SimpleNamespace(simulate=simulate, write_report=write_report, write_recording=write_recording)


def test_failed_run_leaves_only_a_failed_summary(tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    monkeypatch.setattr(run, "model_module", lambda name: _fake_level(fail=False))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 0
    assert json.loads((out / "summary.json").read_text())["status"] == "ok"
    assert {p.name for p in out.iterdir()} == {"summary.json", "timeseries.npz", "report.png", "recording.rrd"}

    monkeypatch.setattr(run, "model_module", lambda name: _fake_level(fail=True))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 3
    err = capsys.readouterr().err
    assert "simulation failed: timestep 1e-3 s exceeds" in err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "stable limit" in summary["message"]
    assert [p.name for p in out.iterdir()] == ["summary.json"]  # stale results removed, no staging left


def test_internal_error_is_not_a_traceback_and_leaves_failed_summary(tmp_path, monkeypatch, capsys):
    def boom(scenario, progress=None):
        raise ZeroDivisionError("x")

    lvl = _fake_level(False)
    lvl.simulate = boom
    monkeypatch.setattr(run, "model_module", lambda name: lvl)
    out = tmp_path / "o"
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 1
    assert "internal error: ZeroDivisionError" in capsys.readouterr().err
    assert json.loads((out / "summary.json").read_text())["status"] == "failed"


def test_summary_has_the_always_keys(tmp_path, monkeypatch):
    monkeypatch.setattr(run, "model_module", lambda name: _fake_level(fail=False))
    s = run.run_scenario(load_scenario(MINIMAL), tmp_path, progress=False)
    for k in ("status", "message", "model", "scenario", "wall_time_s", "sim_time_s", "steps"):
        assert k in s
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    # steps=10 of _fake_level's Result (echoed back)
    assert on_disk["scenario"] == "minimal" and on_disk["steps"] == 10
    assert np.load(tmp_path / "timeseries.npz")["x"].shape == (11,)
