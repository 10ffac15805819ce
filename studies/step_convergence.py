"""The exact-flank runs against the timestep (issue 13; docs/contact3d.md, "Default step for exact flanks"): the seeds'
CI runs (tests/contact3d/test_seeds_pieces.py with contact.geometry flanks; the seat motor's is the demo's 1800 rpm)
and the variety variants (tests/contact3d/test_variety.py), at their default slices, per-step samples (record_every 1).
One JSON line per run, flushed, appended to --out (a run that a guard stops is recorded with its error); the lines of
the study are collected in docs/data/step_convergence.json. Modes:

    --factors 0.5 1 2 4   multiples of today's default step (0.4 x ContactLaw.stable_limit_s, rounded down to 1-2-5)
    --fraction 0.45       h = the fraction x the stable limit, rounded down to 2 digits, and h/2
    --diverge             1-2-5 steps above 2 x the default until the run is unstable (`unstable`), then one between
    --steps 15e-6 ...     these steps, each checked with `unstable` against the default step's run

    .venv/bin/python studies/step_convergence.py --cases screw_jack left-ZA --factors 0.5 1 2 4 --out /tmp/x.jsonl
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from wormsim.contact3d.mass_scaling import floor_2_digits
from wormsim.contact3d.mjcf import build_model, prepare
from wormsim.contact3d.runner import simulate
from wormsim.exceptions import SimulationError
from wormsim.results.metrics import p2p_below
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
BAND_HZ = 1000.0  # F_t's meshing band: below the lowest contact mode measured (involute_41, 1.3-1.8 kHz)
KEYS = (
    "efficiency",
    "ratio",
    "tangential_force_mean_n",
    "tangential_force_p2p_n",
    "transmission_error_p2p_urad",
    "contacts_mean",
    "timestep_stable_limit_s",
    "step_wall_us",
    "flank_slices",
)
DIVERGE_STEPS_S = (1e-5, 2e-5, 5e-5, 1e-4, 2e-4, 5e-4)


def _cases() -> tuple[dict, dict, list, Path, Path]:
    """The test configurations (tests/ on the path only here)."""
    sys.path.insert(0, str(ROOT))
    from tests.conftest import SCENARIOS
    from tests.contact3d.test_seeds_pieces import CI
    from tests.contact3d.test_variety import FAST, FLANK_GEARS, GEAR

    return CI, FLANK_GEARS, FAST, GEAR, SCENARIOS


def overrides(name: str) -> tuple[Path, list[str]]:
    ci, gears, fast, gear, scen = _cases()
    if name in ci:
        return scen / f"{name}.yaml", [*ci[name], "contact.geometry=flanks"]
    return gear, [*fast, *gears[name]]


def default_step_s(name: str) -> float:
    path, ov = overrides(name)
    return build_model(load_scenario(path, ov)).timestep_s


def limit_s(name: str) -> float:
    """ContactLaw.stable_limit_s of the case."""
    path, ov = overrides(name)
    return prepare(load_scenario(path, ov)).law.stable_limit_s


def _finite(v):
    """None for a non-finite float (strict JSON: a ringing run's efficiency can be NaN)."""
    return None if isinstance(v, float) and not math.isfinite(v) else v


def one(name: str, h: float, h0: float) -> dict:
    path, ov = overrides(name)
    sc = load_scenario(path, [*ov, f"simulation.timestep_s={h!r}", "simulation.record_every=1"])
    rec: dict = {"case": name, "timestep_s": h, "factor": h / h0, "default_timestep_s": h0}
    t0 = time.perf_counter()
    try:
        res = simulate(sc)
    except SimulationError as e:
        rec.update(status="failed", error=str(e)[:300], wall_s=time.perf_counter() - t0)
        return rec
    s = res.summary
    t = res.series["t_s"]
    m = (t >= s["steady_window_s"][0]) & (t <= s["steady_window_s"][1])
    rec.update({k: _finite(s.get(k)) for k in KEYS})
    rec.update(
        status="ok",
        tangential_force_p2p_mesh_band_n=p2p_below(t[m], res.series["tangential_force_n"][m], BAND_HZ),
        wall_s=time.perf_counter() - t0,
    )
    return rec


def unstable(rec: dict, ref: dict) -> bool:
    """A guard stopped the run, or it rang undetected: ratio off by more than 0.1 % or F_t p2p over 5 x the default
    step's (measured: the seat motor at 1.24 x the stable limit ran to the end with ratio 52.82 against 53 and F_t
    p2p 3070 N against 0.87 N)."""
    if rec["status"] != "ok":
        return True
    rang = rec["tangential_force_p2p_n"] > 5 * ref["tangential_force_p2p_n"]
    return abs(rec["ratio"] / ref["ratio"] - 1) > 1e-3 or rang


def _write(out: Path, rec: dict) -> None:
    with out.open("a") as fh:
        fh.write(json.dumps(rec) + "\n")
    print(json.dumps(rec), flush=True)


def divergence(name: str, h0: float, out: Path) -> None:
    """The 1-2-5 steps above 2 h0 until the run is unstable, then the geometric mean of the last stable one tried (h0
    at first) and the first unstable step, rounded to 2 digits (bracket further with --steps)."""
    ref = one(name, h0, h0)
    ok = h0
    for h in (h for h in DIVERGE_STEPS_S if h > 2 * h0 * 1.001):
        rec = one(name, h, h0)
        rec["unstable"] = unstable(rec, ref)
        _write(out, rec)
        if rec["unstable"]:
            mid = one(name, float(f"{(ok * h) ** 0.5:.2g}"), h0)
            _write(out, {**mid, "unstable": unstable(mid, ref)})
            return
        ok = h


def main() -> None:
    ci, gears, *_ = _cases()
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="+", default=[*ci, *gears])
    ap.add_argument("--factors", type=float, nargs="+", default=[0.5, 1, 2, 4])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--diverge", action="store_true")
    ap.add_argument("--steps", type=float, nargs="+")
    ap.add_argument("--fraction", type=float)
    a = ap.parse_args()
    for name in a.cases:
        h0 = default_step_s(name)
        if a.diverge:
            divergence(name, h0, a.out)
        elif a.steps:
            ref = one(name, h0, h0)
            for h in a.steps:
                rec = one(name, h, h0)
                _write(a.out, {**rec, "unstable": unstable(rec, ref)})
        elif a.fraction:
            h = floor_2_digits(a.fraction * limit_s(name))
            for step in (h, h / 2):
                _write(a.out, {**one(name, step, h0), "fraction": a.fraction})
        else:
            for f in a.factors:
                _write(a.out, one(name, f * h0, h0))


if __name__ == "__main__":
    main()
