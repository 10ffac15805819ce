"""The scenario checks that need no simulation (wormsim.physics.validate): a gear's geometry is derived and its teeth
checked; an undercut wheel is refused with the field to change; a wedge scenario has no gear to check."""

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
