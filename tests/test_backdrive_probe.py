"""contact3d's back-drive probe (simulation.backdrive_probe): the measured self-locking and back-driving
efficiency against what summary.json states from rho' and gamma."""

from __future__ import annotations

import pytest
from conftest import ROOT

from wormsim.run import simulate
from wormsim.scenario import ScenarioError, load_scenario

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"
PROBE = ["simulation.backdrive_probe=true", "simulation.resolution=coarse"]


def test_probe_measures_the_back_driving_efficiency_of_a_pair_that_does_not_lock():
    # q = 10, z1 = 1: gamma = 5.71 deg; mu 0.05 (default), alpha_n 20 deg: rho' = 3.05 deg; eta' = 0.465 (DIN 3975-2)
    s = simulate(load_scenario(MINIMAL, [*PROBE, "simulation.duration_s=0.03"])).summary
    assert s["self_locking"] is False and s["backdrive_measured_self_locking"] is False
    assert s["efficiency_backdrive"] == pytest.approx(0.4654, abs=1e-4)
    # measured 0.458 (forward: 0.639 against 0.649 at r1, the contacts sit below r1: efficiency_theory_at_contact_radius)
    assert s["backdrive_measured_efficiency"] == pytest.approx(s["efficiency_backdrive"], rel=0.03)


def test_probe_finds_a_self_locking_pair_held():
    # mu 0.2: rho' = atan(0.2 / cos 20 deg) = 12.0 deg > gamma 5.71 deg: the wheel cannot turn the worm
    s = simulate(load_scenario(MINIMAL, [*PROBE, "simulation.duration_s=0.03", "contact.friction=0.2"])).summary
    assert s["self_locking"] is True and s["efficiency_backdrive"] == 0.0
    assert s["backdrive_measured_self_locking"] is True, s["backdrive_measured_message"]
    assert s["backdrive_measured_efficiency"] == 0.0


@pytest.mark.parametrize("sets", [["model=torsional"], ["drive.on=wheel", "load.on=worm"]])
def test_probe_is_refused_where_it_measures_nothing(sets):
    with pytest.raises(ScenarioError, match="backdrive_probe = true: .*allowed: model contact3d with drive.on worm"):
        load_scenario(MINIMAL, ["simulation.backdrive_probe=true", *sets])
