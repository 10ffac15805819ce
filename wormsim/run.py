"""Run one scenario end to end: simulate at the requested fidelity, then write the time series,
report.png, recording.rrd and summary.json atomically (wormsim.runfolder.writer)."""

from __future__ import annotations

import importlib
import sys
import time
from pathlib import Path
from types import ModuleType

import numpy as np

from wormsim.exceptions import ScenarioError, SimulationError
from wormsim.physics.validate import validate_geometry
from wormsim.results import summary_keys as outputs
from wormsim.results.result import Result
from wormsim.results.run_warnings import run_warnings
from wormsim.runfolder import interrupt
from wormsim.runfolder.progress import Progress
from wormsim.runfolder.writer import ResultDir
from wormsim.runtime import prewarm
from wormsim.scenario import Scenario, ignored_inputs

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
    """Simulate `scenario` at its level (`scenario.model`) and return the Result; writes no files.

    Args:
        scenario: a validated Scenario (load_scenario, or Scenario.model_validate of a dict).
        progress: an optional wormsim.runfolder.progress.Progress bar (None: silent).

    Returns:
        Result: `summary` (the keys of docs/outputs.md without the run's status / wall-time keys), `series` (numpy
        arrays on `series["t_s"]` in s; units in the names: `_rad`, `_rpm`, `_nm`, `_n`, `_m`, ...), `steps`,
        `sim_time_s`; `summary["warnings"]` lists results that need care (wormsim.results.run_warnings). Forces follow
        the sign convention of docs/outputs.md.

    Raises:
        ScenarioError: input found invalid on the way (exit 2 at the CLI), e.g. impossible gear geometry.
        SimulationError: the simulation failed, with a diagnosis (diverged, teeth jumped, locked...; exit 3).
    """
    res = model_module(scenario.model).simulate(scenario, progress=progress)
    res.summary["warnings"] = run_warnings(res, scenario)
    return res


def _failed(rd: ResultDir, warm: prewarm.Writers, exc: BaseException, message: str, base: dict, t0: float) -> None:
    """A run that raised exc: the writers' warm-up cancelled; an interrupt that came back as another exception leaves
    out_dir as it was (raised as interrupt.Interrupted), anything else writes a "failed" summary.json with message."""
    warm.cancel()
    if (sig := interrupt.pending()) is not None:
        rd.abandon()
        raise interrupt.Interrupted(sig) from exc
    rd.fail(
        {
            "status": "failed",
            "message": message,
            **base,
            "wall_time_s": time.perf_counter() - t0,
            "sim_time_s": None,
            "steps": None,
        }
    )


def run_scenario(scenario: Scenario, out_dir: str | Path, progress: bool | None = None) -> dict:
    """Simulate `scenario` and write out_dir/{summary.json, timeseries.npz, report.png, recording.rrd}, as
    `wormsim run` does.

    Args:
        scenario: a validated Scenario.
        out_dir: the result folder (created; files replaced atomically; one writer at a time).
        progress: True / False shows / hides the progress bar; None shows it on a terminal.

    Returns:
        dict: the summary as written to summary.json: `status` "ok", `message`, `model`, `scenario`, `wall_time_s`
        [s], `sim_time_s` [s], `steps`, the level's keys and `ignored_inputs` (docs/outputs.md has every key with
        its unit).

    Raises:
        ScenarioError: invalid input, or out_dir cannot be written (exit 2); a "failed" summary.json is written.
        SimulationError: the simulation failed (exit 3); a "failed" summary.json with the diagnosis is written.
        KeyboardInterrupt: Ctrl-C / SIGTERM; out_dir is left as it was.
    """
    validate_geometry(scenario)  # the checks `wormsim check` makes, before anything is written
    ignored = ignored_inputs(scenario)
    rating = None
    if scenario.rating is not None:  # `rating:` at contact3d (wormsim.rating.summary): input errors exit 2 before work
        from wormsim.rating.summary import rating_before_run
        from wormsim.rating.summary import summary_keys as rating_summary_keys

        rating = rating_before_run(scenario)
    mod = model_module(scenario.model)
    simulate_level = mod.simulate  # the level's modules imported here, before the warm-up thread imports beside them
    rd = ResultDir(out_dir)
    base = {"model": scenario.model, "scenario": scenario.name}
    t0 = time.perf_counter()
    # the writers' imports and matplotlib's text warm-up, in a thread while the simulation runs
    # (wormsim.runtime.prewarm)
    warm = prewarm.Writers(gated=getattr(mod, "GIL_FREE_LOOP", False))
    try:
        with Progress(
            scenario.simulation.duration_s, label=f"{scenario.name} ({scenario.model})", enabled=progress
        ) as bar:
            res = simulate_level(scenario, progress=bar)
        wall = time.perf_counter() - t0
        res.summary["warnings"] = run_warnings(res, scenario)  # results to read with care (F_t p2p, off-flank contacts)
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
        _failed(rd, warm, exc, str(exc), base, t0)
        raise
    except BaseException as exc:  # never leave a result that looks complete
        _failed(rd, warm, exc, f"internal error: {exc.__class__.__name__}: {exc}", base, t0)
        raise
    summary = {
        "status": "ok",
        "message": "",
        **base,
        "wall_time_s": wall,
        "sim_time_s": res.sim_time_s,
        "steps": res.steps,
        **res.summary,
        "ignored_inputs": ignored,
        **rated,
    }
    missing = outputs.undocumented(summary)
    if missing:  # every key has its entry in wormsim.results.summary_keys (docs/outputs.md); never written silently
        print(f"wormsim: summary keys without an entry in docs/outputs.md: {', '.join(missing)}", file=sys.stderr)
    rd.commit(summary)
    # never silence: what the level does not use is said after the run (a failed run prints its error alone)
    for line in ignored:
        print(f"wormsim: {line}", file=sys.stderr)
    return summary
