"""The scenario checks that need no simulation (wormsim.physics.validate): a gear's geometry is derived and its teeth
checked; an undercut wheel is refused with the field to change, at the wedge derived from gear: too; a wedge
scenario with its own wedge: block has no gear to check."""

from __future__ import annotations

import pytest

from tests.conftest import SCENARIOS
from wormsim.physics.validate import validate_geometry
from wormsim.scenario import ScenarioError, load_scenario


def test_a_gear_is_derived_and_checked():
    g = validate_geometry(load_scenario(SCENARIOS / "screw_jack.yaml"))
    assert g is not None and g.z2 == load_scenario(SCENARIOS / "screw_jack.yaml").gear.wheel_teeth


def test_an_undercut_wheel_names_the_field_to_raise():
    sc = load_scenario(SCENARIOS / "screw_jack.yaml", ["gear.normal_pressure_angle_deg=5"])
    with pytest.raises(ScenarioError, match=r"undercut.*raise gear\.normal_pressure_angle_deg \(now 5\.00\)"):
        validate_geometry(sc)


def test_a_wedge_scenario_has_no_gear_to_check():
    assert validate_geometry(load_scenario(SCENARIOS / "mov_1.yaml")) is None


def test_the_wedge_derived_from_gear_checks_the_gear(tmp_path, capsys):
    """model wedge without a wedge: block takes the gear's lead angle, radii and inertias: an undercut wheel is
    refused there too (exit 2 naming the field; the random gears' test found wedge runs exit 0 on gears that check,
    torsional and contact3d refuse: a pointed worm thread, a 100 % undercut wheel)."""
    from wormsim import cli

    sets = ["model=wedge", "gear.normal_pressure_angle_deg=5"]
    with pytest.raises(ScenarioError, match=r"undercut.*gear\.normal_pressure_angle_deg"):
        validate_geometry(load_scenario(SCENARIOS / "screw_jack.yaml", sets))
    argv = ["run", str(SCENARIOS / "screw_jack.yaml"), "--out", str(tmp_path / "o"), "--no-progress"]
    assert cli.main(argv + [a for kv in sets for a in ("--set", kv)]) == 2
    assert "gear.normal_pressure_angle_deg" in capsys.readouterr().err
    assert validate_geometry(load_scenario(SCENARIOS / "screw_jack.yaml", ["model=wedge"])) is not None
