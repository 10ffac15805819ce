"""The background warm-ups (wormsim.runtime.prewarm, wormsim.contact3d.jit_warmup): no figure made, no rcParam changed, the
gate holds, a failure does not fail the run (and leaves the GIL switch interval as it was), a failed run's thread does
no work."""

from __future__ import annotations

import sys
import threading
import types
from pathlib import Path

import numpy as np
import pytest

from wormsim import run
from wormsim.contact3d import jit_warmup
from wormsim.results.result import Result
from wormsim.runtime import prewarm
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"


def _level(gated: bool, calls: list, fail: bool = False):
    """A fake fidelity level whose simulate records whether the warm-up ran before its loop started."""

    def simulate(scenario, progress=None):
        calls.append(("simulate", threading.current_thread().name))
        prewarm.loop_started()
        if fail:
            raise ZeroDivisionError("x")
        t = np.linspace(0, 1, 11)
        return Result(model="contact3d", summary={"ratio": 30.0}, series={"t_s": t}, steps=10, sim_time_s=1.0)

    def write_report(res, path):
        calls.append(("report", None))
        Path(path).write_bytes(b"png")

    def write_recording(res, path):
        Path(path).write_bytes(b"rrd")

    return types.SimpleNamespace(
        simulate=simulate, write_report=write_report, write_recording=write_recording, GIL_FREE_LOOP=gated
    )


def test_warm_text_leaks_no_figure_and_changes_no_rcparam():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    before = dict(matplotlib.rcParams)
    figs = plt.get_fignums()
    prewarm.warm_text()
    assert plt.get_fignums() == figs
    assert dict(matplotlib.rcParams) == before


def test_gate_holds_the_work_until_the_loop_starts(monkeypatch):
    done = threading.Event()
    monkeypatch.setattr(prewarm, "_import_writers", done.set)
    monkeypatch.setattr(prewarm, "_text_warmed", True)
    w = prewarm.Writers(gated=True)
    assert not done.wait(0.2)  # gated: nothing imported while the model is built
    prewarm.loop_started()
    w.join()
    assert done.is_set() and not w.thread.is_alive()


def test_warm_up_runs_before_the_writers_and_its_failure_does_not_fail_the_run(tmp_path, monkeypatch):
    calls, seen = [], []

    def boom():
        calls.append(("warm", threading.current_thread().name))
        seen.append(sys.getswitchinterval())
        raise RuntimeError("no fonts")

    monkeypatch.setattr(prewarm, "_import_writers", boom)
    monkeypatch.setattr(run, "model_module", lambda name: _level(True, calls))
    interval = sys.getswitchinterval()
    s = run.run_scenario(load_scenario(MINIMAL), tmp_path, progress=False)
    assert seen == [pytest.approx(min(interval, prewarm.SWITCH_INTERVAL_S), rel=1e-6)]  # short while it holds the GIL
    assert sys.getswitchinterval() == interval  # the process's again
    assert s["status"] == "ok" and (tmp_path / "report.png").read_bytes() == b"png"
    names = [c[0] for c in calls]
    assert names == ["simulate", "warm", "report"]  # joined before the report is drawn
    assert calls[1][1] == "wormsim-prewarm-writers"


def test_a_failed_run_cancels_the_warm_up(tmp_path, monkeypatch):
    calls, made = [], []
    monkeypatch.setattr(prewarm, "_import_writers", lambda: calls.append(("warm", None)))

    class Recorded(prewarm.Writers):
        def __init__(self, gated=False):
            super().__init__(gated)
            made.append(self)

    monkeypatch.setattr(prewarm, "Writers", Recorded)
    lvl = _level(True, calls, fail=True)
    lvl.simulate = lambda scenario, progress=None: 1 / 0  # fails before its loop: the gate never opened
    monkeypatch.setattr(run, "model_module", lambda name: lvl)
    try:
        run.run_scenario(load_scenario(MINIMAL), tmp_path, progress=False)
    except ZeroDivisionError:
        pass
    assert len(made) == 1 and made[0].cancelled and not made[0].thread.is_alive()
    assert calls == []  # no warm-up after a failure (it would draw while a later run's writers do)


def test_cancelled_writers_do_no_work(monkeypatch):
    calls = []
    monkeypatch.setattr(prewarm, "_import_writers", lambda: calls.append("warm"))
    w = prewarm.Writers(gated=True)
    w.cancel()
    assert not w.thread.is_alive() and calls == []


def test_jit_warmup_starts_numba_and_a_failure_is_dropped(monkeypatch):
    jit_warmup.start().join()
    assert jit_warmup._touch.signatures  # loaded or compiled: numba is started

    def boom(x):
        raise RuntimeError("no LLVM")

    monkeypatch.setattr(jit_warmup, "_touch", boom)
    th = jit_warmup.start()
    th.join()
    assert not th.is_alive()
