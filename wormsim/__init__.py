"""wormsim: worm gear drive dynamics with real tooth contact (MuJoCo), and the reduced wedge and torsional models.

Data flows one way: scenario -> geometry (meshgen) -> model -> simulation -> metrics -> recording/report.

    from wormsim import load_scenario, run_scenario
    summary = run_scenario(load_scenario("scenarios/mov_1.yaml"), "out/mov_1")    # writes DIR, returns the summary
    result = simulate(load_scenario("scenarios/mov_1.yaml"))                      # no files: a Result
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
    "load_scenario",
    "run_scenario",
    "simulate",
]
