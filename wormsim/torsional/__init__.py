"""torsional: 2 DOF, worm and wheel rotations coupled by a mesh force element with k(theta) from a tooth contact
analysis of the exact flanks. mesh_stiffness.py (TCA), dynamics.py (equations, integration, summary), report.py.

The package's entry points load on first use (PEP 562), so that importing mesh_stiffness alone (contact3d's default
slice count, flanks.default_slices) does not import dynamics' scipy.integrate (~2.5 s)."""

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
