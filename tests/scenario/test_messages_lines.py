"""The validation messages (wormsim.scenario.messages): one line per problem naming the field, its value and what
is allowed, a misspelt key's nearest names, a size in metres caught, long values cut, at most MAX_PROBLEMS lines."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from wormsim.scenario import Scenario
from wormsim.scenario.messages import MAX_PROBLEMS, MAX_SHOWN, abbreviate, describe_errors, unit_hint


def _message(data) -> str:
    with pytest.raises(ValidationError) as err:
        Scenario.model_validate(data)
    return describe_errors(err.value, "x.yaml", None, Scenario)


BASE = {"name": "x", "model": "torsional", "gear": {"profile": "ZI", "worm_starts": 1, "wheel_teeth": 40,
        "axial_module_mm": 4, "diameter_quotient": 10}, "drive": {"speed_rpm": 1450}, "load": {"torque_nm": 150}}  # fmt: skip


def test_a_misspelt_key_gets_its_nearest_names():
    msg = _message({**BASE, "gear": {**BASE["gear"], "wheel_teth": 40}})
    assert msg.startswith("x.yaml: unknown key 'gear.wheel_teth' (did you mean 'wheel_teeth'")


def test_a_number_out_of_range_names_field_value_and_range():
    msg = _message({**BASE, "gear": {**BASE["gear"], "wheel_teeth": 3}})
    assert msg.startswith("x.yaml: gear.wheel_teeth = 3: ") and "allowed" in msg and len(msg.splitlines()) == 1


def test_a_size_given_in_metres_is_caught():
    assert "looks like metres (4 mm?)" in unit_hint("axial_module_mm", 0.004)
    assert unit_hint("axial_module_mm", 4) == "" and unit_hint("wheel_teeth", 0.004) == ""


def test_long_values_are_cut_and_problems_counted():
    assert abbreviate("a" * 500).endswith("...") and len(abbreviate("a" * 500)) == MAX_SHOWN
    assert abbreviate({"a": 1}) == "{...}" and abbreviate(list(range(50))) == "[...]"
    bad = {**BASE, **{f"extra_{i}": i for i in range(MAX_PROBLEMS + 3)}}
    lines = _message(bad).splitlines()
    assert len(lines) == MAX_PROBLEMS + 1 and lines[-1] == "x.yaml: ... and 3 more problems"
