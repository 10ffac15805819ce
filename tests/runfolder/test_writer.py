"""Output paths, failures and interrupts (issue 10): exit 2 "cannot write to PATH: reason" for a path that
cannot be written, an earlier good result never lost to an interrupt, replaced only by a failed summary when a
run fails, stale staging folders cleaned, one writer per folder."""

from __future__ import annotations

import errno
import json
import os
import types
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import ROOT
from wormsim import cli, run
from wormsim.exceptions import SimulationError
from wormsim.results.result import Result
from wormsim.runfolder import writer as output
from wormsim.runfolder.writer import FolderLock

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"
MOV = ROOT / "scenarios" / "mov_1.yaml"
# exit codes asserted: 0 ok, 2 invalid input, 3 simulation failed, 130 / 143 interrupted (docs/cli.md, INTERFACE.md)


def _level(behaviour: str = "ok"):
    """A stand-in fidelity level: 'ok', 'fail' (SimulationError), 'interrupt' (Ctrl-C during the simulation),
    'interrupt_writing' (Ctrl-C while the report is being written into staging)."""

    def simulate(scenario, progress=None):
        if behaviour == "fail":
            raise SimulationError("diverged at t = 0.1 s")
        if behaviour == "interrupt":
            raise KeyboardInterrupt
        t = np.linspace(0, 1, 11)
        return Result(model="contact3d", summary={"ratio": 30.0}, series={"t_s": t, "x": t}, steps=10, sim_time_s=1.0)

    def write_report(res, path):
        Path(path).write_bytes(b"png-" + behaviour.encode())
        if behaviour == "interrupt_writing":
            raise KeyboardInterrupt

    def write_recording(res, path):
        Path(path).write_bytes(b"rrd-" + behaviour.encode())

    return types.SimpleNamespace(simulate=simulate, write_report=write_report, write_recording=write_recording)


def _snapshot(d: Path) -> dict:
    return {p.name: p.read_bytes() for p in sorted(d.iterdir())}


def _good_result(out: Path, monkeypatch) -> dict:
    monkeypatch.setattr(run, "model_module", lambda name: _level("ok"))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 0
    snap = _snapshot(out)
    assert set(snap) == set(output.RESULT_FILES)
    return snap


# ----------------------------------------------------------------------------- paths


@pytest.mark.parametrize("command", ["run", "mesh", "model"])
def test_out_is_an_existing_file(command, tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_bytes(b"keep me")
    assert cli.main([command, str(MINIMAL), "--out", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: cannot write to {f}: ") and "not a directory" in err and err.count("\n") == 1
    assert f.read_bytes() == b"keep me"


@pytest.mark.parametrize(
    "argv", [["run", str(MOV)], ["mesh", str(MINIMAL)], ["model", str(MINIMAL)], ["bench", "--quick"], ["schema"]]
)
def test_out_under_dev_null(argv, capsys):
    assert cli.main([*argv, "--out", "/dev/null/x"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: cannot write to /dev/null/x: ") and err.count("\n") == 1, err


@pytest.mark.parametrize("command", ["run", "mesh"])
def test_read_only_file_system(command, tmp_path, monkeypatch, capsys):
    """EROFS where the output folder's first file is created (root ignores chmod, so the error is injected)."""

    def erofs(*a, **k):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr(output.tempfile, "mkstemp", erofs)
    assert cli.main([command, str(MOV if command == "run" else MINIMAL), "--out", str(tmp_path / "o")]) == 2
    assert "cannot write to" in (err := capsys.readouterr().err) and "Read-only file system" in err


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders; covered by the EROFS test")
def test_read_only_folder(tmp_path, capsys):
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o555)
    assert cli.main(["run", str(MOV), "--out", str(ro / "o")]) == 2
    assert "Permission denied" in capsys.readouterr().err


def test_schema_out_is_a_directory_or_has_no_parent(tmp_path, capsys):
    assert cli.main(["schema", "--out", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err
    assert cli.main(["schema", "--out", str(tmp_path / "missing" / "s.json")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not (tmp_path / "missing").exists()


# ----------------------------------------------------------------------------- failures and interrupts


def test_failed_run_replaces_an_earlier_result_by_a_failed_summary_only(tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    _good_result(out, monkeypatch)
    monkeypatch.setattr(run, "model_module", lambda name: _level("fail"))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 3
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "failed" and "diverged" in s["message"]


@pytest.mark.parametrize("behaviour", ["interrupt", "interrupt_writing"])
def test_interrupt_leaves_an_earlier_result_untouched(behaviour, tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    before = _good_result(out, monkeypatch)
    capsys.readouterr()
    monkeypatch.setattr(run, "model_module", lambda name: _level(behaviour))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert err.startswith("interrupted") and "internal error" not in err
    assert _snapshot(out) == before  # byte for byte; no staging folder, no lock file left


def test_stale_staging_of_a_killed_run_is_removed(tmp_path, monkeypatch):
    out = tmp_path / "o"
    out.mkdir()
    (out / ".staging-abc123").mkdir()
    (out / ".staging-abc123" / "report.png").write_bytes(b"half")
    (out / ".summary.json.xyz").write_text("{")
    (out / ".recording.rrd.tmp42").write_bytes(b"")
    (out / "notes.txt").write_text("mine")  # a user's own file stays
    monkeypatch.setattr(run, "model_module", lambda name: _level("ok"))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted([*output.RESULT_FILES, "notes.txt"])


def test_second_writer_is_refused_naming_the_holder(tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    before = _good_result(out, monkeypatch)
    capsys.readouterr()
    lock = FolderLock(out)
    lock.acquire()  # as a concurrent run would (flock is per open file, so this process conflicts too)
    try:
        assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 2
        err = capsys.readouterr().err
        assert f"process {os.getpid()} is writing there" in err and err.count("\n") == 1
        assert cli.main(["mesh", str(MINIMAL), "--out", str(out)]) == 2
    finally:
        lock.release()
    assert _snapshot(out) == before
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 0  # free again


def test_lock_is_released_after_a_failure(tmp_path, monkeypatch):
    out = tmp_path / "o"
    monkeypatch.setattr(run, "model_module", lambda name: _level("fail"))
    assert cli.main(["run", str(MINIMAL), "--out", str(out), "--no-progress"]) == 3
    lock = FolderLock(out)
    lock.acquire()
    lock.release()
