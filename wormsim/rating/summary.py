"""The rating keys of a simulation's summary (docs/rating.md: the contact3d summary when `rating:` is given): the
method-B / AGMA keys of wormsim.rating.rate, and beside them the simulation-based safety factors (method C):
safety_pitting_sim from the simulated mean Hertz pressure, safety_root_sim from the FE root stress
(rating.root_stress: fe)."""

from __future__ import annotations

import math

from wormsim.rating.rate import RATING_KEYS, rate
from wormsim.scenario import Scenario

SIM_KEYS = ("root_stress_max_mpa", "root_stress_range_mpa", "safety_pitting_sim", "safety_root_sim")


def rating_before_run(scenario: Scenario) -> dict | None:
    """The rating of a scenario with a `rating:` block run at contact3d (None otherwise); computed before the
    simulation, so that its input errors stop the run before any work (exit 2)."""
    if scenario.rating is None or scenario.model != "contact3d":
        return None
    return rate(scenario)


def pitting_limit_mpa(result: dict) -> float | None:
    for row in result.get("factors", []):
        if row["key"] == "sigma_hg_mpa":
            return float(row["value"])
    return None


def summary_keys(scenario: Scenario, result: dict, sim_summary: dict) -> dict:
    """The rating keys for the summary, with the simulation-based ones: sigma_HG / (simulated mean Hertz pressure
    x sqrt(K_A)) (the simulation runs at the nominal load; Hertz pressure grows with the square root of the load)."""
    assert scenario.rating is not None
    out = {k: result.get(k) for k in RATING_KEYS}
    if scenario.rating.root_stress == "fe":
        from wormsim.rating.fe_root import add_fe_root_stress

        add_fe_root_stress(scenario, result)
    for k in SIM_KEYS:
        out[k] = result.get(k)
    p_sim = sim_summary.get("contact_pressure_mean_mpa")
    s_hg = pitting_limit_mpa(result)
    if s_hg is not None and isinstance(p_sim, float) and math.isfinite(p_sim) and p_sim > 0:
        out["safety_pitting_sim"] = s_hg / (p_sim * math.sqrt(scenario.rating.application_factor))
    out["warnings"] = list(sim_summary.get("warnings", [])) + list(result["warnings"])  # the run's, then the rating's
    out["sources"] = list(result["sources"])
    return out
