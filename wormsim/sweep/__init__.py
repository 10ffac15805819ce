"""Parameter sweeps on dask.distributed (`wormsim sweep`): spec (the sweep file and its points), runner (resume,
sweep.csv / sweep.json), cluster (the local cluster or a scheduler by address), plot (sweep.png).

The names below are imported on first use: `wormsim sweep` imports wormsim.sweep.cluster (light) first, to start the
cluster's fork server before the rest."""

from __future__ import annotations

from typing import TYPE_CHECKING

from wormsim.runtime.lazy import lazy_getattr

if TYPE_CHECKING:
    from wormsim.sweep.runner import run_sweep
    from wormsim.sweep.spec import Point, Sweep, SweepFile, load_sweep

__all__ = ["load_sweep", "run_sweep", "Sweep", "SweepFile", "Point"]
_LAZY = {
    "run_sweep": "wormsim.sweep.runner",
    **dict.fromkeys(("load_sweep", "Sweep", "SweepFile", "Point"), "wormsim.sweep.spec"),
}


__getattr__ = lazy_getattr(__name__, _LAZY)
