"""The wedge level's report.png and recording.rrd (wormsim.wedge.report), written from a short run, read back, and
its entry (wormsim.wedge.level)."""

from __future__ import annotations

from tests._level_report import check_report_and_recording
from tests.conftest import SCENARIOS
from wormsim.scenario import load_scenario
from wormsim.wedge import level as wedge_level
from wormsim.wedge import report as wedge_report


def test_report_and_recording_are_written(tmp_path):
    check_report_and_recording("wedge", wedge_report, tmp_path)


def test_wedge_level_runs_the_seed_block_or_the_derived_model():
    """seed 000's wedge: block goes to wormsim.wedge.dynamics (rho = atan(mu)); a gear without one to the derived
    model (rho' = atan(mu / cos alpha_n)), which states the gear's forces and efficiency."""
    derived = wedge_level.simulate(
        load_scenario(SCENARIOS / "screw_jack.yaml", ["model=wedge", "simulation.duration_s=0.05"])
    ).summary
    assert derived["wedge_source"].startswith("derived from gear:") and 0 < derived["efficiency"] < 1
    seed = load_scenario(SCENARIOS / "mov_1.yaml", ["simulation.duration_s=0.05"])
    assert seed.wedge is not None
    block = wedge_level.simulate(seed).summary
    assert block["wedge_source"].startswith("wedge: block") and "efficiency" not in block
