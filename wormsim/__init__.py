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

from wormsim.runtime import jit_cache as _jit_cache

_jit_cache.configure()  # numba's cache: this machine's folder for this code, before any compiled function exists

from wormsim.exceptions import ScenarioError, SimulationError  # noqa: E402
from wormsim.results.result import Result  # noqa: E402
from wormsim.run import LEVELS, run_scenario, simulate  # noqa: E402
from wormsim.scenario import Scenario, load_scenario  # noqa: E402

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
