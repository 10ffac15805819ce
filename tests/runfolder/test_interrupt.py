"""SIGINT, SIGTERM and SIGKILL sent to a real `wormsim run` (torsional seat motor: seconds per run), and two runs
into one folder (issue 10)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import ROOT
from wormsim.runfolder.writer import RESULT_FILES

SEAT = ROOT / "scenarios" / "seat_motor.yaml"
WORMSIM = Path(sys.executable).with_name("wormsim")
TORSIONAL = ["--set", "model=torsional", "--no-progress"]
# exit codes asserted: 0 ok, 2 invalid input, 3 simulation failed, 130 / 143 interrupted (docs/cli.md, INTERFACE.md)


def _default_sigint():
    # a child of a background job inherits SIGINT ignored (and Python then keeps ignoring it): as on a terminal
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(out: Path, duration_s: float) -> subprocess.Popen:
    return subprocess.Popen(
        [str(WORMSIM), "run", str(SEAT), "--out", str(out), *TORSIONAL, "--set", f"simulation.duration_s={duration_s}"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_sigint,
        env=dict(os.environ, WORMSIM_NO_PROGRESS="1"),
    )


def wait_for_staging(proc: subprocess.Popen, out: Path, timeout_s: float = 120.0) -> None:
    """Until the run has started simulating (its staging folder exists)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout_s:
        if out.is_dir() and any(p.name.startswith(".staging-") for p in out.iterdir()):
            time.sleep(0.3)
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.02)
    raise AssertionError("the run never started")


def snapshot(d: Path) -> dict:
    return {p.name: p.read_bytes() if p.is_file() else "<dir>" for p in sorted(d.iterdir())}


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("good") / "o"
    r = subprocess.run(
        [str(WORMSIM), "run", str(SEAT), "--out", str(out), *TORSIONAL, "--set", "simulation.duration_s=0.5"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    return out, snapshot(out)


def _copy(src: tuple[Path, dict], dst: Path) -> dict:
    dst.mkdir()
    for name, data in src[1].items():
        (dst / name).write_bytes(data)
    return snapshot(dst)


@pytest.mark.parametrize(
    "sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "interrupted (SIGTERM)")]
)
def test_signal_during_rerun_keeps_the_good_result(sig, code, word, good, tmp_path):
    out = tmp_path / "o"
    before = _copy(good, out)
    proc = start(out, 200.0)
    wait_for_staging(proc, out)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    assert err.strip().startswith(word) and "internal error" not in err and "Traceback" not in err, err
    assert snapshot(out) == before


def test_sigkill_leaves_staging_that_the_next_run_removes(good, tmp_path):
    out = tmp_path / "o"
    before = _copy(good, out)
    proc = start(out, 200.0)
    wait_for_staging(proc, out)
    proc.kill()
    proc.communicate(timeout=60)
    assert any(p.name.startswith(".staging-") for p in out.iterdir())
    assert {k: v for k, v in snapshot(out).items() if not k.startswith(".")} == before  # result still there
    r = subprocess.run(
        [str(WORMSIM), "run", str(SEAT), "--out", str(out), *TORSIONAL, "--set", "simulation.duration_s=0.5"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in out.iterdir()) == sorted(RESULT_FILES)
    assert json.loads((out / "summary.json").read_text())["status"] == "ok"


def test_second_run_into_the_same_folder_is_refused(good, tmp_path):
    out = tmp_path / "o"
    before = _copy(good, out)
    first = start(out, 200.0)
    wait_for_staging(first, out)
    try:
        r = subprocess.run(
            [str(WORMSIM), "run", str(SEAT), "--out", str(out), *TORSIONAL, "--set", "simulation.duration_s=0.1"],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert r.returncode == 2, r.stderr
        assert f"process {first.pid} is writing there" in r.stderr and r.stderr.count("\n") == 1, r.stderr
    finally:
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=120)
    assert first.returncode == 143
    assert snapshot(out) == before


def test_interrupt_is_sticky_and_restored():
    """wormsim.runfolder.interrupt: the handler raises Interrupted and records the signal, so a KeyboardInterrupt swallowed
    somewhere (a lazy import's `except BaseException`) resurfaces at the next check(); restore() puts the old
    handlers back and clears it."""
    import pytest

    from wormsim.runfolder import interrupt

    old = interrupt.install()
    try:
        assert signal.getsignal(signal.SIGTERM) is interrupt._handler
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1.0)  # (the handler runs at the next bytecode)
        except interrupt.Interrupted as exc:
            assert exc.signum == signal.SIGTERM and isinstance(exc, KeyboardInterrupt)
        assert interrupt.pending() == signal.SIGTERM
        with pytest.raises(interrupt.Interrupted):
            interrupt.check()  # swallowed once, raised again
    finally:
        interrupt.restore(old)
    assert interrupt.pending() is None and signal.getsignal(signal.SIGTERM) is old.get(signal.SIGTERM, signal.SIG_DFL)
    interrupt.check()  # nothing pending: no raise


def test_an_interrupt_where_python_cannot_raise_it_prints_nothing(monkeypatch):
    """A signal that lands in a weakref callback or a __del__ (importlib's module-lock callback during an import, seen
    in CI as "Exception ignored in: <function _get_module_lock.<locals>.cb>" with a traceback on stderr) reaches
    sys.unraisablehook: while the handler is installed the hook drops an Interrupted (recorded; check() raises it)
    and passes anything else to the hook that was there; restore() puts that hook back."""
    from wormsim.runfolder import interrupt

    seen = []
    monkeypatch.setattr(sys, "unraisablehook", lambda u: seen.append(type(u.exc_value).__name__))

    class Raises:
        def __init__(self, exc):
            self.exc = exc

        def __del__(self):
            raise self.exc

    old = interrupt.install()
    try:
        assert old and sys.unraisablehook is interrupt._unraisable
        Raises(interrupt.Interrupted(signal.SIGINT))  # (dropped at once: __del__ raises)
        Raises(ValueError("not ours"))
    finally:
        interrupt.restore(old)
    assert seen == ["ValueError"]
    assert sys.unraisablehook is not interrupt._unraisable
    Raises(KeyError("after restore"))
    assert seen == ["ValueError", "KeyError"]
