"""N MuJoCo contacts per tooth flank as the default? (issue 33 item 4, decision 0048): the cases of
studies/slice_convergence_default.py (the variety gears, three random gears and the seeds' CI runs with flanks, at
simulation.resolution medium, the default) at their default slice count S per slice and with N contacts per tooth
flank, and each at 2 S (issue 31's criterion: F_t p2p and p_H max within 10 % of 2 S). Per run: F_t mean and p2p, p_H
max, TE p2p, efficiency, F_r, F_a, the MuJoCo contacts per step, the timestep, the CPU seconds of the build
(time.process_time; the first run of a case builds its gear's caches) and of the stepping (time.thread_time around
run_model, per simulated second: the comparison), the kernel compiled before the first case. Writes
docs/data/RECORD.json after each case (a long sweep can be cut).

    .venv/bin/python studies/flank_contacts_default.py [--n 4] [--cases seat_motor ...] [--record NAME]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studies.slice_convergence_default import BAND_HZ, CASES, scenario  # noqa: E402
from wormsim.contact3d.mjcf import build_model, flank_slices  # noqa: E402
from wormsim.contact3d.runner import run_model, warm_runs  # noqa: E402
from wormsim.exceptions import SimulationError  # noqa: E402
from wormsim.results.metrics import p2p_below  # noqa: E402
from wormsim.results.provenance import record  # noqa: E402
from wormsim.runtime import jit_cache  # noqa: E402
from wormsim.scenario import Scenario  # noqa: E402

KEYS = (
    "tangential_force_mean_n",
    "tangential_force_p2p_n",
    "contact_pressure_max_mpa",
    "transmission_error_p2p_urad",
    "efficiency",
    "radial_force_mean_n",
    "axial_force_mean_n",
    "contacts_mean",
    "timestep_s",
    "flank_slices",
    "flank_contacts",
)
CHANGE = ("tangential_force_p2p_n", "contact_pressure_max_mpa")  # issue 31's criterion, S against 2 S


def with_contacts(sc: Scenario, fc: str | int) -> Scenario:
    """The scenario with contact.flank_contacts = fc."""
    return sc.model_copy(update={"contact": sc.contact.model_copy(update={"flank_contacts": fc})})


def measure(sc: Scenario) -> dict:
    """One run: the summary's KEYS, F_t p2p below BAND_HZ, the CPU s of the build (process) and of the stepping (this
    thread: the compiled loop runs in it; studies/measure_step_levers.run_cpu) and the simulated s."""
    c0, t0 = time.process_time(), time.perf_counter()
    bm = build_model(sc)
    build, c1 = time.process_time() - c0, time.thread_time()
    res = run_model(bm)
    cpu, wall = time.thread_time() - c1, time.perf_counter() - t0
    r, S = res.summary, res.series
    t = S["t_s"]
    m = (t >= r["steady_window_s"][0]) & (t <= r["steady_window_s"][1])
    out = {k: r.get(k) for k in KEYS}
    out["ft_p2p_band_n"] = float(p2p_below(t[m], S["tangential_force_n"][m], BAND_HZ))
    return out | {"cpu_s": cpu, "cpu_s_per_sim_s": cpu / res.sim_time_s, "build_cpu_s": build, "wall_s": wall}


def rel(a: float | None, b: float | None) -> float | None:
    return None if a is None or b is None or not b else a / b - 1


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=4, help="MuJoCo contacts per tooth flank")
    ap.add_argument("--cases", nargs="+", default=CASES)
    ap.add_argument("--record", default="flank_contacts_default")
    a = ap.parse_args()
    variants: tuple[str | int, ...] = ("slice", a.n)
    jit_cache.ensure_warm(warm_runs)  # compiled before the first case (wormsim.contact3d.runner.simulate does so)
    warm = scenario("screw_jack", None, True)
    warm = warm.model_copy(update={"simulation": warm.simulation.model_copy(update={"duration_s": 0.002})})
    for v in variants:  # every variant's compiled path loaded before the first measured run
        measure(with_contacts(warm, v))
    out: dict = {
        "what": f"per slice against {a.n} MuJoCo contacts per tooth flank on studies/slice_convergence_default.py's "
        "cases at resolution medium: each at its default slices S and at 2 S; change_vs_slice: N per flank against per "
        "slice at S; change_S_vs_2S: S against 2 S per variant (issue 31: F_t p2p and p_H max within 10 %)",
        "n": a.n,
        "band_hz": BAND_HZ,
        "cases": {},
    }
    for name in a.cases:
        s0 = flank_slices(scenario(name, None, True))
        hertz = False
        try:
            runs = {
                str(v): [measure(with_contacts(scenario(name, s, True), v)) for s in (s0, 2 * s0)] for v in variants
            }
        except SimulationError as e:  # the teeth's compliance fails on this gear (gmsh): Hertz's, as the study does
            print(name, "teeth's compliance failed, Hertz's stiffness:", str(e)[:120], flush=True)
            hertz = True
            runs = {
                str(v): [measure(with_contacts(scenario(name, s, True, True), v)) for s in (s0, 2 * s0)]
                for v in variants
            }
        sl, nf = runs["slice"][0], runs[str(a.n)][0]
        case = {
            "default_slices": s0,
            "hertz_fallback": hertz,
            "runs": runs,
            "change_vs_slice": {k: rel(nf[k], sl[k]) for k in (*KEYS[:7], "ft_p2p_band_n", "cpu_s_per_sim_s")},
            "change_S_vs_2S": {
                v: {k: rel(r[0][k], r[1][k]) for k in (*CHANGE, "ft_p2p_band_n")} for v, r in runs.items()
            },
        }
        out["cases"][name] = case
        pct = {k: None if x is None else round(100 * x, 2) for k, x in case["change_vs_slice"].items()}
        print(name, s0, pct, flush=True)
        print(
            "   S vs 2S",
            {
                v: {k: round(100 * x, 1) for k, x in c.items() if x is not None}
                for v, c in case["change_S_vs_2S"].items()
            },
            flush=True,
        )
        record(a.record, out)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
