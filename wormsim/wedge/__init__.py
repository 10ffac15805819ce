"""wedge: seed 000's 1-DOF two-sided wedge model with three regimes. dynamics.py, report.py."""

from wormsim.wedge.dynamics import simulate
from wormsim.wedge.report import write_recording, write_report

__all__ = ["simulate", "write_report", "write_recording"]
