"""Progress of a run: a tqdm bar on a terminal (shown after 2 s); without a terminal (logs, CI, nohup) one line per
10 % of the simulated time once the run has taken LOG_AFTER_S of wall time, so a long run is never silent.

While numba compiles (wormsim.runtime.jit_cache: the first contact3d run on a machine) the line says so, once, and the
time
estimate leaves the compiling seconds out: the rate is the simulation's, not the compiler's."""

from __future__ import annotations

import os
import sys
import time

from wormsim.runfolder import interrupt
from wormsim.runtime import jit_cache

LOG_AFTER_S = 10.0  # no log lines for runs shorter than this (wall time)
LOG_STEP = 0.1  # fraction of the simulated time between log lines


class Progress:
    """Tracks simulated time; `update(t_s)` with the current simulated time. enabled: None = a bar on a terminal,
    log lines otherwise (both off with WORMSIM_NO_PROGRESS); False = silent; True = the bar."""

    def __init__(self, duration_s: float, label: str = "simulating", enabled: bool | None = None, stream=None):
        self._stream = stream or sys.stderr
        off = bool(os.environ.get("WORMSIM_NO_PROGRESS"))
        tty = self._stream.isatty() if hasattr(self._stream, "isatty") else False
        bar = bool(enabled) if enabled is not None else (tty and not off)
        self._log = enabled is None and not tty and not off
        # (imported here: a sweep's workers simulate without a Progress, and the fork server that preloads their
        # imports skips tqdm's, about 0.03 s on the path before a sweep's first point)
        from tqdm import tqdm

        self._bar = tqdm(
            total=round(duration_s, 6),
            desc=label,
            unit="s(sim)",
            delay=2.0,
            disable=not bar,
            leave=False,
            file=self._stream,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.3g}/{total:.3g} s sim [{elapsed}<{remaining}]",
        )
        self._duration, self._label = duration_s, label
        self._last = 0.0
        self._t0 = time.perf_counter()
        self._next_log = LOG_STEP
        self._c0 = jit_cache.compile_seconds()
        self._compiling_said = False
        jit_cache.add_watcher(self._on_compile)

    def _on_compile(self, started: bool) -> None:
        """numba starts (True) or ends (False) a compile (wormsim.runtime.jit_cache.watch)."""
        if started:
            self._bar.set_description_str(f"{self._label}: compiling", refresh=not self._bar.disable)
            if not self._compiling_said:
                self._compiling_said = True
                self.note(f"{self._label}: {jit_cache.compiling_note()}")
        else:
            self._bar.set_description_str(self._label, refresh=False)

    def compiling(self, text: str) -> None:
        """A warm-up is about to compile (wormsim.runtime.jit_cache.ensure_warm): say so once."""
        if not self._compiling_said:
            self._compiling_said = True
            self.note(f"{self._label}: {text}")

    def restart_clock(self) -> None:
        """The simulation starts now: the estimate's clock from here (after a warm-up that compiled)."""
        self._t0 = time.perf_counter()
        self._c0 = jit_cache.compile_seconds()
        if not self._bar.disable:  # (a disabled tqdm has no clock)
            self._bar.start_t = self._bar.last_print_t = self._bar._time()

    def wall_s(self) -> float:
        """Seconds since the clock started, less the seconds numba spent compiling in them."""
        return time.perf_counter() - self._t0 - (jit_cache.compile_seconds() - self._c0)

    def update(self, t_s: float) -> None:
        interrupt.check()  # an interrupt that a library swallowed ends the run here (wormsim.runfolder.interrupt)
        dt = t_s - self._last
        if dt > 0:
            self._bar.update(dt)
            self._last = t_s
        if self._log and self._duration > 0 and t_s / self._duration >= self._next_log:
            frac = t_s / self._duration
            wall = time.perf_counter() - self._t0
            if wall >= LOG_AFTER_S:
                left = max(0.0, self.wall_s() * (1 - frac) / max(frac, 1e-9))  # the compiling seconds left out
                print(
                    f"{self._label}: {100 * frac:3.0f} % ({t_s:.4g} of {self._duration:.4g} s simulated), "
                    f"{wall / 60:.1f} min elapsed, about {left / 60:.1f} min left",
                    file=self._stream,
                    flush=True,
                )
            while self._next_log <= frac:
                self._next_log += LOG_STEP

    def note(self, text: str) -> None:
        """A line the user must see before the run (e.g. mass scaling), unless progress is off (WORMSIM_NO_PROGRESS,
        --no-progress: the summary still says it)."""
        if self._log or not self._bar.disable:
            print(text, file=self._stream, flush=True)

    def close(self) -> None:
        jit_cache.remove_watcher(self._on_compile)
        self._bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
