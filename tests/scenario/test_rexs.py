"""REXS in and out (wormsim.scenario.rexs): the FVA Workbench worm stage (tests/assets/rexs, Apache-2.0, NOTICE.md) and a
second stage written for these tests (other_worm_stage.rexsj: ZA, 1/40, m_n given, x2 from a = 63 mm, finite bearing
stiffnesses), both encodings, the round trip, bad files with exit 2, and the levels' F_t2 = T2 / (d2 / 2)."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest

from wormsim import cli
from wormsim.physics.geometry import derive
from wormsim.runfolder.writer import write_rexs
from wormsim.scenario import ScenarioError, load_scenario, rexs, scenario_from_dict

ASSETS = Path(__file__).parents[1] / "assets" / "rexs"
FVA_XML = ASSETS / "FVA_worm_stage_1-4.rexs"
FVA_JSON = ASSETS / "FVA_worm_stage_1-4.rexsj"
OTHER = ASSETS / "other_worm_stage.rexsj"


def _core(data: dict) -> dict:
    """The scenario without the lines that name the file it came from."""
    return {k: v for k, v in data.items() if k not in ("name", "description")}


def test_fva_stage_imports_as_the_file_gives_it():
    imp = rexs.import_file(FVA_XML)
    sc = scenario_from_dict(imp.data)
    g = derive(sc.gear)
    assert g.a * 1e3 == pytest.approx(100.0, abs=1e-9)
    assert g.ratio == pytest.approx(20.5, abs=1e-12)
    assert (g.d1 * 1e3, g.d2 * 1e3, g.face_width * 1e3) == pytest.approx((36.0, 164.0, 30.0), abs=1e-9)
    assert (2e3 * g.r_a2, 2e3 * g.r_f2) == pytest.approx((172.0, 154.4), abs=1e-9)  # the file's wheel tip / root
    assert sc.gear.profile == "ZI" and sc.gear.hand == "left" and sc.gear.profile_shift_coefficient == 0.0
    assert sc.drive.on == "worm" and sc.drive.speed_rpm == 1000.0
    assert sc.load.on == "wheel" and sc.load.torque_nm == 300.0
    # bearings at u = 70 / 230 around the worm at u = 150; the wheel's at u = 60 / 140 around u = 100
    assert sc.shafts.worm.bearings_mm == [-80.0, 80.0] and sc.shafts.worm.bending
    assert sc.shafts.wheel.bearings_mm == [-40.0, 40.0]
    assert sc.shafts.worm.radial_stiffness_n_per_um is None  # 1e20 N/m: rigid
    r = sc.rating
    assert (r.lubricant, r.oil_viscosity_40_mm2_s, r.oil_viscosity_100_mm2_s) == ("peg", 220.0, 37.0)
    assert r.oil_sump_temperature_c == 73.2 and r.life_h == 100000.0
    assert r.wheel_pitting_strength_mpa is None  # the steel placeholder's 1500 MPa is not a bronze's strength
    assert any("16MnCr5" in n and "placeholder" in n for n in imp.notes)  # the steel wheel is called out
    text = rexs.to_yaml(imp)
    assert "axial_module_mm: 4.0  # worm_gear[8].axial_module = 4 mm" in text
    unused = [ln for ln in text.splitlines() if ln.startswith("# not used: ")]
    assert len(unused) == 1 and "shaft_section[240].outer_diameter_begin" in unused[0]


def test_both_encodings_give_the_same_scenario():
    assert _core(rexs.import_file(FVA_XML).data) == _core(rexs.import_file(FVA_JSON).data)


def test_another_stage_other_teeth_module_form_torque_speed_centre_distance():
    sc = scenario_from_dict(rexs.import_file(OTHER).data)
    g = derive(sc.gear)
    assert (sc.gear.profile, sc.gear.hand, g.z1, g.z2) == ("ZA", "right", 1, 40)
    assert g.m_x * 1e3 == pytest.approx(2.5, abs=1e-12)  # from the normal module and the lead angle
    assert g.x2 == pytest.approx(0.2, abs=1e-12) and g.a * 1e3 == pytest.approx(63.0, abs=1e-9)
    assert 2e3 * g.r_a2 == pytest.approx(106.0, abs=1e-9)  # d_a2 = d2 + 2 m_x (1 + x2)
    assert 2e3 * g.r_e2 == pytest.approx(108.0, abs=1e-9)  # the file's outer_diameter_worm_wheel (default 108.5)
    # ZA: the file's 20 deg is the axial pressure angle
    assert math.degrees(g.alpha_x) == pytest.approx(20.0, abs=1e-8)
    assert (sc.drive.speed_rpm, sc.load.torque_nm) == (1400.0, 80.0)
    assert sc.shafts.worm.radial_stiffness_n_per_um == 500.0 and sc.shafts.worm.axial_stiffness_n_per_um == 300.0
    assert sc.rating.wheel_material == "CuSn12Ni2" and sc.rating.application_factor == 1.25
    assert sc.rating.wheel_pitting_strength_mpa == 400.0  # the bronze's endurance_limit_flank


@pytest.mark.parametrize("src", [FVA_XML, OTHER])
@pytest.mark.parametrize("suffix", [".rexs", ".rexsj"])
def test_round_trip_import_export_import_is_identical(src, suffix, tmp_path):
    first = rexs.import_file(src)
    sc = scenario_from_dict(first.data)
    out = write_rexs(rexs.export_model(sc), tmp_path / f"back{suffix}")
    second = rexs.import_file(out)
    assert _core(second.data) == _core(first.data)


@pytest.mark.parametrize("model", ["wedge", "torsional"])
@pytest.mark.parametrize("src", [FVA_JSON, OTHER])
def test_levels_give_ft2_from_the_wheel_torque(model, src):
    """F_t2 = T2 / (d2 / 2) within 0.5 % (the FVA stage: 300 N m on d2 164 mm = 3658.5 N)."""
    from wormsim import simulate

    sc = load_scenario(src, overrides=[f"model={model}", "simulation.duration_s=0.3"])
    g = derive(sc.gear)
    s = simulate(sc).summary
    assert s["tangential_force_mean_n"] == pytest.approx(sc.load.torque_nm / g.r2, rel=5e-3)
    assert s["ratio"] == pytest.approx(g.ratio, rel=1e-3)


def test_rate_reads_the_rexs_file(tmp_path):
    assert cli.main(["rate", str(FVA_XML), "--out", str(tmp_path / "r")]) == 0
    r = json.loads((tmp_path / "r" / "rating.json").read_text())
    assert r["inputs"]["oil_sump_temperature_given_c"] == 73.2
    assert r["oil_temperature_c"] == 73.2  # injection lubrication: the given oil temperature
    assert r["safety_pitting"] > 0 and r["safety_root"] > 0


def test_rate_takes_the_files_pitting_strength():
    """The second stage's bronze gives endurance_limit_flank = 400 MPa: sigma_HlimT, and S_H scales with it."""
    from wormsim.rating.rate import rate

    sc = load_scenario(OTHER)
    r = rate(sc)
    row = next(f for f in r["factors"] if f["key"] == "sigma_hlim_t_mpa")
    assert row["value"] == 400.0 and "input" in row["source"]
    table = rate(load_scenario(OTHER, ["rating.wheel_pitting_strength_mpa=null"]))
    t_row = next(f for f in table["factors"] if f["key"] == "sigma_hlim_t_mpa")
    assert r["safety_pitting"] / table["safety_pitting"] == pytest.approx(400.0 / t_row["value"], rel=1e-12)


def test_import_command_writes_a_runnable_commented_scenario(tmp_path, capsys):
    out = tmp_path / "fva.yaml"
    assert cli.main(["import", str(FVA_JSON), "--out", str(out)]) == 0
    assert "16MnCr5" in capsys.readouterr().err
    sc = load_scenario(out)
    assert sc.gear.wheel_teeth == 41 and sc.shafts is not None


def test_run_of_the_fva_file_says_the_wheel_is_a_placeholder(tmp_path, capsys):
    out = str(tmp_path / "run")
    assert cli.main(["run", str(FVA_XML), "--out", out, "--no-progress", "--set", "model=wedge"]) == 0
    assert "16MnCr5" in capsys.readouterr().err


def test_run_writes_rexs_with_results(tmp_path):
    out = tmp_path / "stage.rexs"
    code = cli.main(
        ["run", str(OTHER), "--out", str(tmp_path / "run"), "--no-progress", "--set", "model=wedge", "--rexs", str(out)]
    )
    assert code == 0
    m = rexs.read_model(out)
    stage = next(c for c in m.components.values() if c.type == "worm_stage")
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert stage.attrs["gear_ratio"].value == pytest.approx(summary["ratio"])
    assert stage.attrs["nominal_tangential_force_at_reference_circle"].value == pytest.approx(
        summary["tangential_force_mean_n"]
    )
    for attr in ("safety_factor_pitting_din_3996_2019", "gear_efficiency_in_reducer_din_3996_2019"):
        assert 0 < stage.attrs[attr].value
    # the results do not disturb the stage: it imports to the same scenario
    assert _core(rexs.import_file(out).data) == _core(rexs.import_file(OTHER).data)


def _two_stage_model(tmp_path) -> Path:
    doc = json.loads(OTHER.read_text())
    comps = doc["model"]["components"]
    comps.append({"id": 999, "type": "worm_stage", "name": "second", "attributes": []})
    p = tmp_path / "two.rexsj"
    p.write_text(json.dumps(doc))
    return p


def _no_module(tmp_path) -> Path:
    text = FVA_XML.read_text(encoding="utf-8")
    text = text.replace('<attribute id="axial_module" unit="mm">4.0</attribute>', "")
    text = text.replace('<attribute id="normal_module" unit="mm">3.90475</attribute>', "")
    p = tmp_path / "nomodule.rexs"
    p.write_text(text, encoding="utf-8")
    return p


def _text(name: str, text: str):
    def make(d: Path) -> Path:
        (d / name).write_text(text)
        return d / name

    return make


def _cylindrical(tmp_path) -> Path:
    p = tmp_path / "cyl.rexsj"
    comps = [{"id": 1, "type": "cylindrical_gear_stage", "name": "s", "attributes": []}]
    comps += [{"id": i, "type": "cylindrical_gear", "name": "g", "attributes": []} for i in (2, 3)]
    p.write_text(json.dumps({"model": {"version": "1.4", "applicationId": "x", "relations": [], "components": comps}}))
    return p


@pytest.mark.parametrize(
    "make, match",
    [
        (_text("x.rexs", "gear: 1\n"), "neither XML"),
        (_text("y.rexs", "<model version='1.4'><components>"), "XML error"),
        (_cylindrical, "no worm stage .*1 cylindrical_gear_stage"),
        (_two_stage_model, "2 worm stages"),
        (_no_module, r"worm_gear\[8\]\.axial_module is missing"),
    ],
)
def test_bad_rexs_exits_2_naming_the_problem(make, match, tmp_path, capsys):
    path = make(tmp_path)
    assert cli.main(["import", str(path), "--out", str(tmp_path / "o.yaml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert re.search(match, err), err
    with pytest.raises(ScenarioError):
        load_scenario(path)  # `wormsim run FILE.rexs` refuses it the same way


def test_rexs_version_2_is_refused():
    with pytest.raises(ScenarioError, match="allowed: REXS 1.x"):
        rexs.parse('{"model": {"version": "2.0", "components": [], "relations": []}}', "v2.rexsj")


@pytest.mark.parametrize("name", ["contact3d_fva", "contact3d_other"])
def test_stages_at_contact3d_with_shafts(name):
    """Both stages at contact3d on their bearings, 0.1 s: F_t2 = T2 / (d2 / 2) within 0.5 %, ratio, efficiency
    against the wedge law at the contacts' radius (3 %), the worm's axial bearing load F_a1 = F_t2 (measured, FVA with
    the worm shaft bending: F_t2 3657.1 N of 3658.5, efficiency 0.7860 against 0.7866, worm deflection at the mesh
    24 um; the second stage on compliant bearings: 1599.9 N of 1600, 0.6383 against 0.6390)."""
    from wormsim.contact3d.runner import simulate

    src = FVA_JSON if name == "contact3d_fva" else OTHER
    sc = load_scenario(src, ["model=contact3d", "simulation.duration_s=0.1", "drive.ramp_s=0.02", "load.ramp_s=0.02"])
    assert sc.shafts is not None and sc.shafts.worm.bending == (name == "contact3d_fva")
    g = derive(sc.gear)
    s = simulate(sc).summary
    assert s["tangential_force_mean_n"] == pytest.approx(sc.load.torque_nm / g.r2, rel=5e-3)
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3
    assert abs(s["efficiency"] / s["efficiency_theory_at_contact_radius"] - 1) < 0.03
    assert s["worm_bearing_axial_mean_n"] == pytest.approx(s["tangential_force_mean_n"], rel=0.01)
    assert s["worm_deflection_mesh_um"] > 0


def test_shipped_fva_scenario_is_the_import():
    """scenarios/fva_worm_stage_1-4.yaml is `wormsim import tests/assets/rexs/FVA_worm_stage_1-4.rexs` as it is."""
    shipped = Path(__file__).parents[2] / "scenarios" / "fva_worm_stage_1-4.yaml"
    assert shipped.read_text() == rexs.to_yaml(rexs.import_file(FVA_XML))
    assert load_scenario(shipped) == load_scenario(FVA_XML)


def test_shafts_are_ignored_and_reported_below_contact3d():
    from wormsim.scenario import ignored_inputs

    sc = load_scenario(FVA_JSON)
    assert sc.model == "torsional" and sc.shafts is not None
    assert any(line.startswith("shafts: ignored") for line in ignored_inputs(sc))
    assert not any("shafts" in line for line in ignored_inputs(load_scenario(FVA_JSON, ["model=contact3d"])))
