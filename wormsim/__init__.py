"""wormsim: worm gear drive dynamics with real tooth contact (MuJoCo), and the reduced wedge and torsional models.

Data flows one way: scenario -> geometry (meshgen) -> model -> simulation -> metrics -> recording/report.

    import wormsim

    sc = wormsim.load_scenario("my_gear.yaml", ["model=torsional"])  # validated; ScenarioError names a bad field
    sc.load.torque_nm = 80  # validated on assignment
    res = wormsim.simulate(sc)  # no files: a Result
    res.summary["efficiency"], res.summary["self_locking"]  # docs/outputs.md: every key, unit, sign
    res.series["t_s"], res.series["tangential_force_n"]  # numpy arrays on t_s
    summary = wormsim.run_scenario(sc, "out/my_gear")  # writes summary.json, timeseries.npz, ...

The reference: docs/api.md (generated from these docstrings), docs/scenario.md, docs/outputs.md.

The worm pair as a component of a MuJoCo model of one's own: wormsim.WormPair (wormsim.pair, docs/multibody.md).
"""

from typing import TYPE_CHECKING

from wormsim.runtime import jit_cache as _jit_cache

_jit_cache.configure()  # numba's cache: this machine's folder for this code, before any compiled function exists

from wormsim.exceptions import ScenarioError, SimulationError  # noqa: E402
from wormsim.runtime.lazy import lazy_getattr  # noqa: E402

if TYPE_CHECKING:
    from wormsim.pair import WormPair, step
    from wormsim.results.result import Result
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

# Each public name is imported on first use, so that `import wormsim.x` of a light module (the console script's
# parser, `wormsim sweep`'s cluster start) does not load the simulation's modules (numba, MuJoCo, pydantic's schema).
_LAZY = {
    "LEVELS": "wormsim.run",
    "run_scenario": "wormsim.run",
    "simulate": "wormsim.run",
    "Result": "wormsim.results.result",
    "Scenario": "wormsim.scenario",
    "load_scenario": "wormsim.scenario",
    "WormPair": "wormsim.pair",  # MuJoCo and the compiled kernel
    "step": "wormsim.pair",
}


__getattr__ = lazy_getattr(__name__, _LAZY)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
