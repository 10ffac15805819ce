"""Errors that point at the cause: a unit hint for gear sizes given in metres, "did you mean" for a misspelt key,
refusals that name the keys the user gave, explicit material defaults, validation on assignment."""

from __future__ import annotations

import pytest

from tests.conftest import ROOT
from tools.schema_doc import markdown
from wormsim import cli
from wormsim.scenario import Materials, ScenarioError, load_scenario

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"
# exit codes asserted: 0 ok, 2 invalid input, 3 simulation failed, 130 / 143 interrupted (docs/cli.md, INTERFACE.md)


def run_err(tmp_path, capsys, *sets: str) -> str:
    argv = ["run", str(MINIMAL), "--out", str(tmp_path), "--no-progress", "--set", "model=torsional"]
    assert cli.main(argv + [x for s in sets for x in ("--set", s)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


def test_a_module_in_metres_gets_a_unit_hint_not_a_backlash_message(tmp_path, capsys):
    err = run_err(tmp_path, capsys, "gear.axial_module_mm=0.003")
    assert "gear.axial_module_mm = 0.003" in err and "allowed: 0.05 <= axial_module_mm <= 50" in err
    assert "looks like metres (3 mm?)" in err and "backlash" not in err


@pytest.mark.parametrize(
    "setting, names",
    [
        ("gear.face_width_mm=0.02", "gear.face_width_mm = 0.02: narrower than one module"),
        ("gear.worm_length_mm=0.05", "gear.worm_length_mm = 0.05: allowed"),  # meshgen's refusal, hint added
    ],
)
def test_other_gear_sizes_in_metres_get_the_hint(tmp_path, capsys, setting, names):
    err = run_err(tmp_path, capsys, setting)
    assert names in err and "looks like metres" in err


def test_a_small_backlash_is_no_unit_mistake(tmp_path, capsys):
    err = run_err(tmp_path, capsys, "gear.backlash_mm=5")  # too large for a 2 mm module; 0.05 mm is a backlash
    assert "gear.backlash_mm = 5" in err and "metres" not in err


@pytest.mark.parametrize(
    "setting, suggestion",
    [
        ("gear.wheel_teth=30", "unknown key 'gear.wheel_teth' (did you mean 'wheel_teeth'?)"),
        ("drive.sped_rpm=3", "unknown key 'drive.sped_rpm' (did you mean 'speed_rpm'?)"),
        ("modle=wedge", "unknown key 'modle' (did you mean 'model'?)"),
    ],
)
def test_a_misspelt_key_gets_did_you_mean(tmp_path, capsys, setting, suggestion):
    assert suggestion in run_err(tmp_path, capsys, setting)


def test_a_derived_size_refusal_names_the_key_given(tmp_path, capsys):
    # q = 2 with dedendum 1.2 m: root radius m (q / 2 - 1.2) < 0.2 r1; the limit is q >= 2.5 * 1.2 = 3.0
    err = run_err(tmp_path, capsys, "gear.diameter_quotient=2")
    assert err.startswith("error: gear.diameter_quotient = 2: allowed diameter_quotient >= 3.0")
    assert "lead angle" not in err
    # given as a lead angle: the refusal is about lead_angle_deg (limit atan(1 / 3.0) = 18.4 deg)
    err = run_err(tmp_path, capsys, "gear.diameter_quotient=null", "gear.lead_angle_deg=40")
    assert "gear.lead_angle_deg = 40" in err and "lead_angle_deg <= 18.4" in err
    err = run_err(tmp_path, capsys, "gear.lead_angle_deg=5")
    assert "give exactly one of lead_angle_deg / diameter_quotient: both given" in err


def test_material_defaults_are_explicit_in_the_schema_and_its_doc():
    m = Materials()
    assert (m.worm.youngs_modulus_gpa, m.wheel.youngs_modulus_gpa) == (210, 100)
    doc = markdown()
    assert "default steel: 210 GPa, 0.3, 7850 kg/m^3" in doc and "default tin bronze: 100 GPa" in doc
    assert "| `materials` | block | see block |  | optional" in doc


def test_objects_validate_on_assignment():
    sc = load_scenario(MINIMAL)
    with pytest.raises(ScenarioError, match=r"axial_module_mm = -3: .*allowed: 0.05 <= axial_module_mm <= 50"):
        sc.gear.axial_module_mm = -3
    assert sc.gear.axial_module_mm == 2  # unchanged
    with pytest.raises(ScenarioError, match="give exactly one of normal_module_mm / axial_module_mm"):
        sc.gear.normal_module_mm = 1.0
    assert sc.gear.normal_module_mm is None  # the refused assignment left the block as it was
    with pytest.raises(ScenarioError, match="simulation: duration = 1.0: Object has no attribute 'duration'"):
        sc.simulation.duration = 1.0
    sc.gear.axial_module_mm = 3  # a valid value is taken
    assert sc.gear.axial_module_mm == 3


def test_a_refused_default_names_the_key_left_out(tmp_path, capsys):
    # z2 10, q 40: the default face width 0.75 d_a1 = 0.75 x 84 mm = 63 mm exceeds the small wheel's root (24.8 mm)
    err = run_err(tmp_path, capsys, "gear.wheel_teeth=10", "gear.diameter_quotient=40")
    assert "gear.face_width_mm not given: its default 63.000 mm" in err and "allowed up to 24.775 mm" in err
