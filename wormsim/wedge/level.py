"""The wedge level's entry: seed 000's wedge: block (wormsim.wedge.dynamics), or the reduced model derived from
gear:, drive:, load: when the scenario has no wedge: block (wormsim.wedge.derive)."""

from __future__ import annotations

from wormsim.results.result import Result
from wormsim.wedge import derive, dynamics


def simulate(scenario, progress=None) -> Result:
    """Integrate the wedge model of `scenario` (model: wedge) and return series and summary."""
    if scenario.wedge is None:
        return derive.simulate_derived(scenario, progress)
    return dynamics.simulate(scenario, progress)
