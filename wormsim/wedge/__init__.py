"""wedge: seed 000's 1-DOF two-sided wedge model with three regimes. level.py (the entry), dynamics.py,
derive.py (from gear:), report.py."""

from wormsim.wedge.level import simulate
from wormsim.wedge.report import write_recording, write_report

__all__ = ["simulate", "write_report", "write_recording"]
