"""What every fidelity level's `simulate()` returns, so that the runner, the report and the
recording treat wedge, torsional and contact3d alike."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Result:
    """What simulate() returns, the same for every level.

    Attributes:
        model: the level: "wedge", "torsional" or "contact3d".
        summary: the level's summary.json keys (docs/outputs.md: unit, meaning, sign of each).
        series: time series, numpy arrays sampled on series["t_s"] [s]; units in the names (`worm_speed_rpm`,
            `wheel_torque_nm`, `tangential_force_n`, ...); forces on the wheel in docs/outputs.md's signs.
        steps: integrator steps taken.
        sim_time_s: simulated time reached [s].
        extra: level-specific data for the report and the recording (not a stable interface).
    """

    model: str
    summary: dict  # model-specific summary.json keys (docs/outputs.md)
    series: dict[str, np.ndarray]  # time series, all sampled on series["t_s"]
    steps: int  # integrator steps taken
    sim_time_s: float
    extra: dict = field(default_factory=dict)  # model-specific data for the report/recording
