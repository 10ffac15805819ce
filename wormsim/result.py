"""What every fidelity level's `simulate()` returns, so that the runner, the report and the
recording treat wedge, torsional and contact3d alike."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Result:
    model: str
    summary: dict  # model-specific summary.json keys (INTERFACE.md)
    series: dict[str, np.ndarray]  # time series, all sampled on series["t_s"]
    steps: int  # integrator steps taken
    sim_time_s: float
    extra: dict = field(default_factory=dict)  # model-specific data for the report/recording
