"""contact3d's back-drive probe (simulation.backdrive_probe): the measured self-locking and back-driving
efficiency against what summary.json states from rho' and gamma."""

from __future__ import annotations

import pytest

from meshgen.geometry import derive
from tests.conftest import ROOT
from wormsim.physics.gear_theory import efficiency_at_radius
from wormsim.run import simulate
from wormsim.scenario import ScenarioError, load_scenario

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"
PROBE = ["simulation.backdrive_probe=true", "simulation.resolution=coarse"]


def test_probe_measures_the_back_driving_efficiency_of_a_pair_that_does_not_lock():
    # q = 10, z1 = 1: gamma = 5.71 deg; mu 0.05 (default), alpha_n 20 deg: rho' = 3.05 deg; eta' = 0.465 (DIN 3975-2)
    # at r1. 600 rpm, 0.2 s: 2 meshing periods (a fraction of one swings the measured value by +-30 %)
    sc = load_scenario(MINIMAL, [*PROBE, "simulation.duration_s=0.2", "contact.friction=0.05"])
    s = simulate(sc).summary
    assert s["self_locking"] is False and s["backdrive_measured_self_locking"] is False
    assert s["efficiency_backdrive"] == pytest.approx(0.4654, abs=1e-4)
    # the contacts sit above r1 (a smaller lead angle): eta' at the forward run's contact radius (measured 0.4394
    # against 0.4395 there with the teeth's compliance, 0.4390 against 0.4392 with Hertz; 0.465 at r1; at 3000 rpm
    # and 0.1 s the teeth's 0.428 against 0.440)
    g = derive(sc.gear)
    at_contacts = efficiency_at_radius(
        g.gamma, g.r1, s["worm_contact_radius_mean_m"], sc.contact.friction, g.alpha_n, backdriving=True
    )
    assert s["backdrive_measured_efficiency"] == pytest.approx(at_contacts, rel=0.01)


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


def test_probe_scenario_swaps_drive_and_load_and_reads_the_held_worm():
    """wormsim.contact3d.backdrive: the probe drives the wheel at the forward run's wheel speed and loads the worm
    with T2 eta' / i; a worm below HELD_BELOW of the wheel command times the ratio is a measured self-locking, a lock
    error too, and otherwise the probe's efficiency is the measured back-driving efficiency."""
    from types import SimpleNamespace

    from wormsim.contact3d import backdrive
    from wormsim.exceptions import LockedError

    sc = load_scenario(MINIMAL, PROBE)
    fwd = {"wheel_speed_mean_rpm": 15.0, "efficiency_backdrive": 0.45, "ratio_theory": 40.0}
    p = backdrive.probe_scenario(sc, fwd)
    assert p.drive.on == "wheel" and p.drive.speed_rpm == 15.0 and p.load.on == "worm"
    assert p.load.torque_nm == pytest.approx(abs(sc.load.torque_nm) * 0.45 / 40.0)
    assert p.simulation.backdrive_probe is False  # no probe of the probe

    def runs_at(worm_rpm):
        return lambda s: SimpleNamespace(summary={"worm_speed_mean_rpm": worm_rpm, "efficiency": 0.44})

    free = backdrive.probe(sc, fwd, runs_at(15.0 * 40.0 * 0.98))
    assert free["backdrive_measured_self_locking"] is False and free["backdrive_measured_efficiency"] == 0.44
    held = backdrive.probe(sc, fwd, runs_at(15.0 * 40.0 * (backdrive.HELD_BELOW - 0.01)))
    assert held["backdrive_measured_self_locking"] is True and held["backdrive_measured_efficiency"] == 0.0

    def locks(s):
        raise LockedError("drive locked")

    locked = backdrive.probe(sc, fwd, locks)
    assert locked["backdrive_measured_self_locking"] is True and "drive locked" in locked["backdrive_measured_message"]
