"""torsional: 2 DOF, worm and wheel rotations coupled by a mesh force element with k(theta) from a tooth contact
analysis of the exact flanks. mesh_stiffness.py (TCA), dynamics.py (equations, integration, summary), report.py."""

from wormsim.torsional.dynamics import simulate
from wormsim.torsional.report import write_recording, write_report

__all__ = ["simulate", "write_report", "write_recording"]
