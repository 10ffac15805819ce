"""Parameter sweeps on dask.distributed (`wormsim sweep`): spec (the sweep file and its points), runner (the
cluster, resume, sweep.csv / sweep.json), plot (sweep.png)."""

from wormsim.sweep.runner import run_sweep
from wormsim.sweep.spec import Point, Sweep, SweepFile, load_sweep

__all__ = ["load_sweep", "run_sweep", "Sweep", "SweepFile", "Point"]
