"""Work done in a background thread while a simulation runs, so that it costs no wall time on a second core.

`Writers` imports what the writers use (matplotlib ~0.7 s, rerun ~0.6 s) and warms matplotlib's text machinery (the
default font and the mathtext parser that the log axis's tick labels need: ~0.1 s of report.png's ~1.4 s; the rest,
tight_layout's text layout and the draw, costs as much again on a second report in one process). Python code only
gains from a thread while the main thread has released the GIL: contact3d's compiled stepping loop does
(wormsim.contact3d.flank_loop.run_table), the model build before it mostly does not, so a package that sets
GIL_FREE_LOOP holds the thread until its runner calls `loop_started()` (else the imports would slow the build).
run_scenario joins the thread before writing (matplotlib is not thread-safe); a failed run cancels it. A failure in
the thread is dropped: the writers import and draw for themselves.
"""

from __future__ import annotations

import importlib
import sys
import threading

SWITCH_INTERVAL_S = 2e-4  # the GIL switch interval while the thread works (module docstring)
JOIN_TIMEOUT_S = 60.0  # a warm-up that hangs must not hang the run

_gate: threading.Event | None = None  # the running Writers' gate (one run at a time per process)
_text_warmed = False  # warm_text runs once per process


def loop_started() -> None:
    """Called by a runner when its GIL-free loop starts: lets the waiting warm-up go."""
    if _gate is not None:
        _gate.set()


def _import_writers() -> None:
    import matplotlib

    matplotlib.use("Agg")
    importlib.import_module("matplotlib.pyplot")
    importlib.import_module("rerun")


def warm_text() -> None:
    """Load the default font and build matplotlib's mathtext parser (the log axis's tick labels are mathtext): the
    first-use costs report.png pays (~0.1 s; a whole throwaway figure, tight_layout and draw, saved no more and cost
    0.4 s). No figure is made, no rcParam set."""
    from matplotlib import font_manager
    from matplotlib.font_manager import FontProperties
    from matplotlib.mathtext import MathTextParser

    prop = FontProperties(size=10.0)
    font_manager.get_font(font_manager.findfont(prop))
    MathTextParser("agg").parse(r"$\mathdefault{10^{-2}}$", dpi=100, prop=prop)


def in_dask_worker() -> bool:
    """True in a task of a dask.distributed worker (wormsim sweep). There the warm-up thread is not started: the
    worker's own threads (its GC diagnosis callback among them) and a second thread importing extension modules beside
    the task's imports can deadlock CPython's import (seen: numpy.fft beside matplotlib, a sweep point that never
    ended), and a sweep's parallelism is across processes anyway."""
    if "distributed" not in sys.modules:
        return False
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return False
    return True


class Writers:
    """The writers' warm-up thread of one run (module docstring). gated: wait for loop_started() (or release())."""

    def __init__(self, gated: bool = False):
        global _gate
        self.gate = threading.Event()
        if not gated:
            self.gate.set()
        _gate = self.gate
        self.error: BaseException | None = None
        self.cancelled = False
        self.thread = threading.Thread(target=self._run, name="wormsim-prewarm-writers", daemon=True)
        if not in_dask_worker():  # a sweep's worker: no warm-up thread (in_dask_worker)
            self.thread.start()

    def _run(self) -> None:
        global _text_warmed
        self.gate.wait()
        if self.cancelled:
            return
        # CPython's GIL convoy: each time the loop's thread comes back from its compiled call it waits for this
        # thread to give up the GIL, up to the switch interval (5 ms, against the loop's ~2.6 ms per sample)
        interval = sys.getswitchinterval()
        sys.setswitchinterval(min(interval, SWITCH_INTERVAL_S))
        try:
            _import_writers()
            if not _text_warmed:
                warm_text()
                _text_warmed = True
        except Exception as exc:  # the writers import and draw for themselves
            self.error = exc
        finally:
            sys.setswitchinterval(interval)

    def release(self) -> None:
        self.gate.set()

    def cancel(self) -> None:
        """The run failed: the thread ends without work (it must not draw while a later run's writers do)."""
        self.cancelled = True
        self.join()

    def join(self) -> None:
        """Let the thread go if it still waits, and wait for it (before anything uses matplotlib)."""
        global _gate
        self.gate.set()
        if self.thread.ident is not None:
            self.thread.join(JOIN_TIMEOUT_S)
        if _gate is self.gate:
            _gate = None
