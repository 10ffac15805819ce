"""Progress of a run: a tqdm bar on a terminal (shown after 2 s); without a terminal (logs, CI, nohup) one line per
10 % of the simulated time once the run has taken LOG_AFTER_S of wall time, so a long run is never silent."""

from __future__ import annotations

import os
import sys
import time

from tqdm import tqdm

from wormsim import interrupt

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

    def update(self, t_s: float) -> None:
        interrupt.check()  # an interrupt that a library swallowed ends the run here (wormsim.interrupt)
        dt = t_s - self._last
        if dt > 0:
            self._bar.update(dt)
            self._last = t_s
        if self._log and self._duration > 0 and t_s / self._duration >= self._next_log:
            frac = t_s / self._duration
            wall = time.perf_counter() - self._t0
            if wall >= LOG_AFTER_S:
                left = max(0.0, wall * (1 - frac) / max(frac, 1e-9))
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
        self._bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
