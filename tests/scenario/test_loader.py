"""Scenario schema: valid files load; each class of bad input is a one-line error naming the field
and what is allowed (INTERFACE.md, issue 'Foundation')."""

import pytest
import yaml

from tests.conftest import ROOT
from wormsim.scenario import ScenarioError, apply_overrides, json_schema, load_scenario, scenario_from_dict

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"


def base() -> dict:
    return yaml.safe_load(MINIMAL.read_text())


def error_of(data: dict) -> str:
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(data, "t.yaml")
    return str(exc.value)


@pytest.mark.parametrize("path", sorted((ROOT / "scenarios").glob("*.yaml")), ids=lambda p: p.stem)
def test_every_shipped_scenario_validates(path):
    sc = load_scenario(path)
    assert sc.name == path.stem or sc.name.startswith(path.stem.split("_")[0])


def test_minimal_scenario_gets_documented_defaults():
    sc = load_scenario(MINIMAL)
    assert sc.gear.profile == "ZI" and sc.gear.hand == "right" and sc.gear.worm_starts == 1
    assert sc.drive.on == "worm" and sc.load.on == "wheel"  # `on:` is not YAML 1.1's boolean True
    assert sc.simulation.timestep_s is None  # chosen by the runner, stated in the summary


def test_wrong_type_names_field():
    d = base()
    d["gear"]["wheel_teeth"] = "many"
    msg = error_of(d)
    assert "gear.wheel_teeth" in msg and '"many"' in msg and "integer" in msg


def test_missing_field_names_field():
    d = base()
    del d["gear"]["wheel_teeth"]
    assert "missing required field 'gear.wheel_teeth'" in error_of(d)


@pytest.mark.parametrize(
    "block,key,value,allowed",
    [
        ("gear", "lead_angle_deg", 50, "less than 45"),
        ("gear", "normal_pressure_angle_deg", 2, "greater than or equal to 5"),
        ("gear", "backlash_mm", -0.1, "greater than or equal to 0"),
    ],
)
def test_out_of_range_gear_value(block, key, value, allowed):
    d = base()
    d[block][key] = value
    if key == "lead_angle_deg":
        del d["gear"]["diameter_quotient"]
    msg = error_of(d)
    assert f"{block}.{key} = {value}" in msg and allowed in msg


def test_negative_mass_and_density():
    d = {"name": "w", "model": "wedge", "wedge": {"driven_mass_kg": -100}}
    msg = error_of(d)
    assert "wedge.driven_mass_kg = -100" in msg and "greater than 0" in msg
    d = base()
    d["materials"] = {"wheel": {"youngs_modulus_gpa": 3.1, "poisson_ratio": 0.39, "density_kg_m3": -1}}
    assert "materials.wheel.density_kg_m3 = -1" in error_of(d)


def test_unknown_friction_group():
    msg = error_of({"name": "w", "model": "wedge", "wedge": {"friction_group": "IV"}})
    assert "wedge.friction_group" in msg and "'I', 'II' or 'III'" in msg
    d = base()
    d["contact"] = {"friction_group": "IV"}
    assert "contact.friction_group" in error_of(d)


def test_unknown_key_is_an_error_not_ignored():
    d = base()
    d["gear"]["colour"] = "red"
    assert "unknown key 'gear.colour'" in error_of(d)
    d = base()
    d["simulaton"] = {"duration_s": 1}
    assert "unknown key 'simulaton'" in error_of(d)


@pytest.mark.parametrize(
    "change,expect",
    [
        ({"normal_module_mm": 2}, "exactly one of normal_module_mm / axial_module_mm"),
        ({"lead_angle_deg": 5}, "exactly one of lead_angle_deg / diameter_quotient"),
    ],
)
def test_exactly_one_of(change, expect):
    d = base()
    d["gear"].update(change)
    assert expect in error_of(d)


def test_cross_field_rules():
    d = base()
    d["load"]["on"] = "worm"
    assert "must name different shafts" in error_of(d)
    d = base()
    d["drive"]["torque_nm"] = 1
    assert "exactly one of speed_rpm / torque_nm" in error_of(d)
    d = base()
    del d["gear"]
    assert "needs a gear: block" in error_of(d)
    assert "needs a wedge: block" in error_of({"name": "w", "model": "wedge"})
    d = base()
    d["contact"] = {"friction_static": 0.05, "friction_dynamic": 0.08}
    assert "friction_dynamic must not exceed friction_static" in error_of(d)


def test_bad_name_and_model():
    d = base()
    d["name"] = "Bad Name"
    assert 'name = "Bad Name"' in error_of(d)
    d = base()
    d["model"] = "fem"
    assert 'model = "fem"' in error_of(d) and "'contact3d'" in error_of(d)


def test_set_overrides_by_dotted_path():
    sc = load_scenario(MINIMAL, ["gear.wheel_teeth=41", "simulation.duration_s=0.5", "contact.friction=0.1"])
    assert sc.gear.wheel_teeth == 41 and sc.simulation.duration_s == 0.5 and sc.contact.friction == 0.1
    sc = load_scenario(MINIMAL, ["drive.on=wheel", "load.on=worm"])
    assert sc.drive.on == "wheel"


def test_set_errors_are_clear():
    with pytest.raises(ScenarioError, match="expected KEY=VALUE"):
        load_scenario(MINIMAL, ["gear.wheel_teeth"])
    with pytest.raises(ScenarioError, match="unknown key 'gear.teeth'"):
        load_scenario(MINIMAL, ["gear.teeth=41"])
    with pytest.raises(ScenarioError, match="'gear.wheel_teeth' is not a block"):
        apply_overrides(base(), ["gear.wheel_teeth.x=1"])


def test_bad_files(tmp_path):
    with pytest.raises(ScenarioError, match="no such scenario file"):
        load_scenario(tmp_path / "nope.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    with pytest.raises(ScenarioError, match="not valid YAML at line"):
        load_scenario(bad)
    lst = tmp_path / "list.yaml"
    lst.write_text("- 1\n- 2\n")
    with pytest.raises(ScenarioError, match="top level must be a mapping"):
        load_scenario(lst)


def test_json_schema_exports_every_block():
    s = json_schema()
    for block in ("Gear", "Contact", "Drive", "Load", "Simulation", "Wedge", "Material"):
        assert block in s["$defs"]
    assert s["$defs"]["Gear"]["additionalProperties"] is False
