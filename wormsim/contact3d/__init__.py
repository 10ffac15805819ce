"""contact3d: worm and wheel on hinges in MuJoCo, coupled only by tooth contact.

law.py (contact-law mapping), mjcf.py (the MjSpec model), backlash.py (checks before a run), runner.py (stepping,
guards), metrics.py (summary), report.py (report.png, recording.rrd)."""

from wormsim.contact3d.report import write_recording, write_report
from wormsim.contact3d.runner import simulate

# the stepping loop runs without the GIL: wormsim.run's warm-up thread waits for it (wormsim.runtime.prewarm)
GIL_FREE_LOOP = True

__all__ = ["simulate", "write_report", "write_recording"]
