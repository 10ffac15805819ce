"""`wormsim bench`: cases.py (the grid), run.py (timing, bench.json, chart), stability.py (the stability edge)."""

from wormsim.bench.run import run_bench

__all__ = ["run_bench"]
