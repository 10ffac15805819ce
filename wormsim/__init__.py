"""wormsim: worm gear drive dynamics with real tooth contact (MuJoCo), and the reduced wedge and torsional models.

Data flows one way: scenario -> geometry (meshgen) -> model -> simulation -> metrics -> recording/report.

    from wormsim import load_scenario, run_scenario
    summary = run_scenario(load_scenario("scenarios/mov_1.yaml"), "out/mov_1")    # writes DIR, returns the summary
    result = simulate(load_scenario("scenarios/mov_1.yaml"))                      # no files: a Result

The worm pair as a component of a MuJoCo model of one's own: wormsim.WormPair (wormsim.pair, docs/multibody.md).
"""

from wormsim.errors import ScenarioError, SimulationError
from wormsim.result import Result
from wormsim.run import LEVELS, run_scenario, simulate
from wormsim.scenario import Scenario, load_scenario

__version__ = "0.1.0"
__all__ = [
    "LEVELS",
    "Result",
    "Scenario",
    "ScenarioError",
    "SimulationError",
    "WormPair",
    "load_scenario",
    "run_scenario",
    "simulate",
    "step",
]

_PAIR = ("WormPair", "step")  # wormsim.pair, imported on first use (it loads MuJoCo and the compiled kernel)


def __getattr__(name: str):
    if name in _PAIR:
        from wormsim import pair

        return getattr(pair, name)
    raise AttributeError(f"module 'wormsim' has no attribute {name!r}")
