"""torsional: 2 DOF, worm and wheel rotations coupled by a mesh force element with k(theta) from a tooth contact
analysis of the exact flanks (wormsim.tooth.mesh_stiffness, wormsim.tooth's kernel for the loaded TCA). dynamics.py
(equations, integration, summary), loaded_tca.py, report.py.

The package's entry points load on first use (PEP 562): importing the package does not import dynamics'
scipy.integrate (~2.5 s)."""

from __future__ import annotations

__all__ = ["simulate", "write_report", "write_recording"]


def __getattr__(name: str):
    if name == "simulate":
        from wormsim.torsional.dynamics import simulate

        return simulate
    if name in ("write_report", "write_recording"):
        from wormsim.torsional import report

        return getattr(report, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
