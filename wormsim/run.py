"""Run one scenario end to end: simulate at the requested fidelity, then write the time series,
report.png, recording.rrd and summary.json atomically (wormsim.output)."""

from __future__ import annotations

import importlib
import time
from pathlib import Path
from types import ModuleType

import numpy as np

from wormsim import interrupt, prewarm
from wormsim.errors import ScenarioError, SimulationError
from wormsim.output import ResultDir
from wormsim.progress import Progress
from wormsim.result import Result
from wormsim.scenario import Scenario
from wormsim.validate import validate_geometry

# fidelity level -> its package, which exports simulate(scenario, progress) -> Result, write_report(result, path) and
# write_recording(result, path). Imported on first use (importlib, not at the top): a wedge run does not load MuJoCo.
LEVELS = {
    "wedge": "wormsim.wedge",
    "torsional": "wormsim.torsional",
    "contact3d": "wormsim.contact3d",
}


def model_module(name: str) -> ModuleType:
    return importlib.import_module(LEVELS[name])


def simulate(scenario: Scenario, progress: Progress | None = None) -> Result:
    """Simulate only (no files): for tests and the benchmark."""
    return model_module(scenario.model).simulate(scenario, progress=progress)


def run_scenario(scenario: Scenario, out_dir: str | Path, progress: bool | None = None) -> dict:
    """Simulate and write DIR/{summary.json, timeseries.npz, report.png, recording.rrd}.

    Returns the summary. Raises SimulationError / ScenarioError after writing a "failed" summary (which replaces
    an earlier result); an interrupt (KeyboardInterrupt, SIGTERM via the CLI) leaves DIR as it was
    (wormsim.output).
    """
    validate_geometry(scenario)  # the checks `wormsim check` makes, before anything is written
    rating = None
    if scenario.rating is not None:  # `rating:` at contact3d (wormsim.rating.summary): input errors exit 2 before work
        from wormsim.rating.summary import rating_before_run
        from wormsim.rating.summary import summary_keys as rating_summary_keys

        rating = rating_before_run(scenario)
    mod = model_module(scenario.model)
    rd = ResultDir(out_dir)
    base = {"model": scenario.model, "scenario": scenario.name}
    t0 = time.perf_counter()
    # the writers' imports and matplotlib's text warm-up, in a thread while the simulation runs (wormsim.prewarm)
    warm = prewarm.Writers(gated=getattr(mod, "GIL_FREE_LOOP", False))
    try:
        with Progress(
            scenario.simulation.duration_s, label=f"{scenario.name} ({scenario.model})", enabled=progress
        ) as bar:
            res = mod.simulate(scenario, progress=bar)
        wall = time.perf_counter() - t0
        rated = {} if rating is None else rating_summary_keys(scenario, rating, res.summary)
        warm.release()
        np.savez_compressed(rd.path("timeseries.npz"), **res.series)
        warm.join()
        mod.write_report(res, rd.path("report.png"))
        mod.write_recording(res, rd.path("recording.rrd"))
        interrupt.check()  # an interrupt swallowed on the way (a library's `except BaseException`)
    except KeyboardInterrupt:  # Ctrl-C / SIGTERM: not a failure of the run; an earlier result stays
        warm.cancel()
        rd.abandon()
        raise
    except (SimulationError, ScenarioError) as exc:  # a diagnosis (exit 3) or input found invalid (exit 2)
        warm.cancel()
        if (sig := interrupt.pending()) is not None:
            rd.abandon()
            raise interrupt.Interrupted(sig) from exc
        rd.fail(
            {
                "status": "failed",
                "message": str(exc),
                **base,
                "wall_time_s": time.perf_counter() - t0,
                "sim_time_s": None,
                "steps": None,
            }
        )
        raise
    except BaseException as exc:  # never leave a result that looks complete
        warm.cancel()
        if (sig := interrupt.pending()) is not None:  # the interrupt came back as another exception
            rd.abandon()
            raise interrupt.Interrupted(sig) from exc
        rd.fail(
            {
                "status": "failed",
                "message": f"internal error: {exc.__class__.__name__}: {exc}",
                **base,
                "wall_time_s": time.perf_counter() - t0,
                "sim_time_s": None,
                "steps": None,
            }
        )
        raise
    summary = {
        "status": "ok",
        "message": "",
        **base,
        "wall_time_s": wall,
        "sim_time_s": res.sim_time_s,
        "steps": res.steps,
        **res.summary,
        **rated,
    }
    rd.commit(summary)
    return summary
