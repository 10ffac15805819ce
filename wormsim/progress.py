"""A progress bar for runs longer than a few seconds (tqdm, on stderr, shown after 2 s)."""
from __future__ import annotations

import os
import sys

from tqdm import tqdm


class Progress:
    """Tracks simulated time; `update(t_s)` with the current simulated time."""

    def __init__(self, duration_s: float, label: str = "simulating", enabled: bool | None = None):
        if enabled is None:
            enabled = sys.stderr.isatty() and not os.environ.get("WORMSIM_NO_PROGRESS")
        self._bar = tqdm(total=round(duration_s, 6), desc=label, unit="s(sim)", delay=2.0,
                         disable=not enabled, leave=False, file=sys.stderr,
                         bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.3g}/{total:.3g} s sim [{elapsed}<{remaining}]")
        self._last = 0.0

    def update(self, t_s: float) -> None:
        dt = t_s - self._last
        if dt > 0:
            self._bar.update(dt)
            self._last = t_s

    def close(self) -> None:
        self._bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

