"""The load-capacity rating (wormsim.rating): public benchmarks, the seeds, `wormsim rate` and its input errors.

Benchmarks (docs/rating.md names them with their sources):
* Niemann/Winter, Maschinenelemente vol. III, example 3, as recomputed by dsoftcon WormGear (dsoftcon.be/WormGear,
  forces and load-capacity output pages): z 1/40, d1 83.20 mm, d2 416.80 mm, mineral oil ISO VG 320, Ra1 0.8 um,
  L_h 25 000 h, K_A 1; v_g 6.59 m/s, mu_z 0.026 (rho_z 1.4954 deg), efficiency 0.82 worm driving / 0.79 wheel
  driving, start-up mu 0.120 / efficiency 0.503.
* Mott, Machine Elements in Mechanical Design, section 10-13 (AGMA 6034): D_G 8.667 in, D_W 2.000 in, m_G 17.33,
  F 1.25 in, V_s 944 ft/min, sand-cast bronze; chart factors C_s 740, C_m 0.814, C_v 0.265 give W_t = 1123 lb.
"""

from __future__ import annotations

import json
import math

import pytest

from tests.conftest import SCENARIOS
from wormsim import cli
from wormsim.rating import RATING_KEYS, rate
from wormsim.rating import agma6034 as agma
from wormsim.rating import iso14521 as iso
from wormsim.scenario import scenario_from_dict

# Niemann/Winter example 3: d2 = z2 m_x -> m_x = 416.8 / 40 = 10.42 mm; q = d1 / m_x = 83.2 / 10.42. The example's
# worm speed is not in the public recomputation: n1 = 1500 min^-1 is the speed that gives its v_g = 6.59 m/s to three
# digits (1490 gives 6.54, 1510 gives 6.63), a common 4-pole motor speed.
NIEMANN = {
    "name": "niemann_winter_3",
    "gear": {
        "profile": "ZI",
        "worm_starts": 1,
        "wheel_teeth": 40,
        "axial_module_mm": 10.42,
        "diameter_quotient": 83.2 / 10.42,
    },
    "materials": {"worm": {"youngs_modulus_gpa": 210, "poisson_ratio": 0.3, "density_kg_m3": 7850}},
    "drive": {"on": "worm", "speed_rpm": 1500},
    "load": {"on": "wheel", "torque_nm": 3000},
    "rating": {"lubricant": "mineral", "oil_viscosity_40_mm2_s": 320, "roughness_worm_um": 0.8, "life_h": 25000},
}


def _niemann(**rating):
    data = json.loads(json.dumps(NIEMANN))
    data["rating"].update(rating)
    return scenario_from_dict(data)


def test_niemann_sliding_speed():
    r = rate(_niemann(wheel_material="CuSn12Ni2"))
    assert round(r["sliding_speed_m_s"], 2) == 6.59  # dsoftcon: v_g 6.59 m/s


def test_niemann_efficiency_formulas_at_the_reference_friction():
    """The efficiency formulas at the example's own friction values (dsoftcon): mu_z 0.026 -> rho_z 1.4954 deg,
    efficiency 0.82 / 0.79; start-up mu 0.120 -> efficiency 0.503."""
    gamma = math.atan(1 / (83.2 / 10.42))
    mu = math.tan(math.radians(1.4954))  # rho_z as dsoftcon prints it (mu_z 0.026 is that, rounded)
    assert round(mu, 3) == 0.026
    assert round(iso.efficiency_worm_driving(gamma, mu), 2) == 0.82
    assert round(iso.efficiency_wheel_driving(gamma, mu), 2) == 0.79
    assert round(iso.efficiency_worm_driving(gamma, 0.120), 3) == 0.503


@pytest.mark.xfail(
    strict=True,
    reason=(
        "mu_zm = 0.0239 (CuSn12Ni2, Y_W 0.95) / 0.0251 (CuSn12, Y_W 1.0) against dsoftcon's 0.026 (-8.2 % / -3.4 %; "
        "efficiency 0.837 / 0.830 against 0.82). mu_0T 0.0341 (v_gm 6.59 m/s), Y_S 0.632 (a = 250 mm) and Y_R 1.125 "
        "(Ra1 0.8 um) follow the public formulas; the gap is in Y_G = sqrt(0.07 / h*) = 1.036, through h*, which grows "
        "with the wheel face width b2H. The example's b2H and wheel material are not in the public pages: we take "
        "meshgen's default b2H = 0.75 d_a1 = 78 mm; with CuSn12, b2H 60 / 62.5 mm would give 0.0261 / 0.0259 "
        "(measured), which meets the reference's rounding (+-0.0005), but choosing b2H to meet it is no check"
    ),
)
@pytest.mark.parametrize("material", ["CuSn12Ni2", "CuSn12"])
def test_niemann_mean_friction(material):
    r = rate(_niemann(wheel_material=material))
    assert abs(r["friction_iso"] - 0.026) <= 0.0005  # dsoftcon: mu_z 0.026


def test_niemann_mean_friction_within_ten_percent():
    """What the public fit gives: within 10 % of dsoftcon's mu_z 0.026 for either tin bronze (the reasons of the
    difference are in test_niemann_mean_friction's xfail)."""
    for material in ("CuSn12Ni2", "CuSn12"):
        r = rate(_niemann(wheel_material=material))
        assert r["friction_iso"] == pytest.approx(0.026, rel=0.10)


def test_mott_agma_example_chart_values():
    """Mott 10-13: W_t = C_s D_m^0.8 F_e C_m C_v with the chart values C_s 740, C_m 0.814, C_v 0.265 -> 1123 lb."""
    f_e = agma.effective_face_width_in(1.25, 2.0)
    assert f_e == 1.25  # F = 1.25 in < 0.67 x 2.000 in
    assert agma.rated_tangential_force_lbf(740.0, 8.667, f_e, 0.814, 0.265) == pytest.approx(1123, abs=1)


def test_mott_agma_example_factor_formulas():
    """The factor formulas against Mott's chart readings: C_s 742.6 vs 740 (+0.4 %), C_m 0.816 vs 0.814, C_v 0.2665
    vs 0.265: W_t 1136 lb against the chart's 1123 lb (+1.1 %, the charts' reading; the reference notes about
    1135 lb from the formulas)."""
    c_s = agma.materials_factor("sand", 8.667, (8.667 + 2.0) / 2)
    c_m = agma.ratio_factor(17.33)
    c_v = agma.velocity_factor(944.0)
    assert c_s == pytest.approx(740, rel=0.005)
    assert c_m == pytest.approx(0.814, rel=0.005)
    assert c_v == pytest.approx(0.265, rel=0.01)
    w_t = agma.rated_tangential_force_lbf(c_s, 8.667, 1.25, c_m, c_v)
    assert w_t == pytest.approx(1135, rel=0.002)  # the reference's formula value
    assert w_t == pytest.approx(1123, rel=0.015)  # Mott's chart value


def test_agma_friction_and_efficiency_limits():
    """Shigley's friction: 0.15 at rest, decreasing with speed; efficiency (cos phi - f tan l)/(cos phi + f cot l)
    is 1 without friction."""
    assert agma.friction(0.0) == 0.15
    assert agma.friction(10.0) > agma.friction(100.0) > agma.friction(3000.0)
    assert agma.efficiency_worm_driving(math.radians(20), math.radians(10), 0.0) == pytest.approx(1.0)


def test_base_friction_falls_with_sliding_speed():
    """Mechanical Engineer's Data Handbook p. 111 (hard steel on phosphor bronze): mu falls 0.06 / 0.05 / 0.035 /
    0.023 / 0.017 / 0.014 at 0.5 / 1 / 2 / 5 / 10 / 20 m/s; so does the DIN 3996 base fit of every oil (its
    magnitude is the test gear's at a = 100 mm, before the factors Y_S ... Y_R, so only the trend is compared)."""
    speeds = (0.5, 1.0, 2.0, 5.0, 10.0, 20.0)
    for oil in ("mineral", "pao", "peg"):
        mus = [iso.base_friction(v, oil, grey_iron=False) for v in speeds]
        assert all(b < a for a, b in zip(mus, mus[1:]))


def test_contact_stress_scales_with_the_square_root_of_torque():
    lo = rate(_niemann(wheel_material="CuSn12Ni2"))
    data = json.loads(json.dumps(NIEMANN))
    data["load"]["torque_nm"] = 4 * 3000
    hi = rate(scenario_from_dict(data))
    assert hi["contact_stress_mean_iso_mpa"] == pytest.approx(2 * lo["contact_stress_mean_iso_mpa"], rel=1e-12)
    assert hi["safety_root"] == pytest.approx(lo["safety_root"] / 4, rel=1e-12)


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack", "involute_41"])
def test_seeds_rate(name, tmp_path, capsys):
    code = cli.main(["rate", str(SCENARIOS / f"{name}.yaml"), "--out", str(tmp_path)])
    assert code == 0
    out = json.loads((tmp_path / "rating.json").read_text())
    assert set(RATING_KEYS) <= set(out)
    md = (tmp_path / "rating.md").read_text()
    assert "## Safety factors" in md and "## Sources" in md
    if name == "seat_motor":  # POM wheel: refused with the reason, no bronze formula applied
        assert out["refused"] and "plastic" in out["refused"]
        assert out["safety_pitting"] is None and out["safety_root"] is None
    else:
        for key in ("safety_pitting", "safety_root", "safety_deflection", "safety_temperature"):
            assert out[key] > 0
        assert 0 < out["efficiency_iso"] < 1
    if name in ("seat_motor", "screw_jack"):  # a < 50 mm: method B outside its recommended range
        assert any("method A" in w for w in out["warnings"])


@pytest.mark.parametrize(
    "override, field",
    [
        ("rating.life_h=0", "rating.life_h"),
        ("rating.application_factor=0.5", "rating.application_factor"),
        ("rating.wheel_material=Brass", "rating.wheel_material"),
        ("rating.lubricant=water", "rating.lubricant"),
        ("rating.root_stress=yes", "rating.root_stress"),
    ],
)
def test_bad_rating_input_exits_2_with_one_line(override, field, tmp_path, capsys):
    code = cli.main(["rate", str(SCENARIOS / "screw_jack.yaml"), "--out", str(tmp_path), "--set", override])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and field in err
    assert not (tmp_path / "rating.json").exists()


def test_torque_drive_needs_a_rating_speed(tmp_path, capsys):
    code = cli.main(
        [
            "rate",
            str(SCENARIOS / "screw_jack.yaml"),
            "--out",
            str(tmp_path),
            "--set",
            "drive.speed_rpm=null",
            "--set",
            "drive.torque_nm=1",
        ]
    )
    assert code == 2 and "rating.worm_speed_rpm" in capsys.readouterr().err


def test_validity_warning_above_25_m_s():
    r = rate(_niemann(wheel_material="CuSn12Ni2", worm_speed_rpm=8000))
    assert r["sliding_speed_m_s"] > 25
    assert any("25 m/s" in w for w in r["warnings"])


def test_summary_keys_with_a_simulated_pressure():
    """The contact3d summary's rating keys (wormsim.rating.summary): the method-B keys, and safety_pitting_sim =
    sigma_HG / (simulated mean Hertz pressure x sqrt(K_A))."""
    from wormsim.rating.summary import SIM_KEYS, pitting_limit_mpa, rating_before_run, summary_keys

    sc = _niemann(wheel_material="CuSn12Ni2", application_factor=1.44)
    rating = rating_before_run(sc)
    assert rating is not None
    keys = summary_keys(sc, rating, {"contact_pressure_mean_mpa": 250.0})
    assert set(RATING_KEYS) | set(SIM_KEYS) <= set(keys)
    assert keys["safety_pitting_sim"] == pytest.approx(pitting_limit_mpa(rating) / (250.0 * 1.2))
    assert keys["safety_root_sim"] is None  # root_stress: none
    nan = summary_keys(sc, rating, {"contact_pressure_mean_mpa": float("nan")})
    assert nan["safety_pitting_sim"] is None


def test_run_with_bad_rating_input_exits_2_before_any_work(tmp_path, capsys):
    code = cli.main(
        [
            "run",
            str(SCENARIOS / "screw_jack.yaml"),
            "--out",
            str(tmp_path),
            "--no-progress",
            "--set",
            "drive.speed_rpm=null",
            "--set",
            "drive.torque_nm=1",
            "--set",
            "rating.life_h=1000",
        ]
    )
    assert code == 2 and "rating.worm_speed_rpm" in capsys.readouterr().err
    assert not (tmp_path / "summary.json").exists()


def test_rating_files_hold_the_result_and_a_readable_report(tmp_path):
    """wormsim.rating.output: rating.json is the result with the scenario's name; rating.md has a row per safety
    factor with the value as rated, every factor with its source, and the warnings."""
    from wormsim.rating.output import SAFETY_ROWS, write_rating
    from wormsim.scenario import load_scenario

    res = rate(load_scenario(SCENARIOS / "screw_jack.yaml"))
    json_path, md_path = write_rating(tmp_path, res, "screw_jack")
    assert json.loads(json_path.read_text()) == json.loads(json.dumps({"scenario": "screw_jack", **res}))
    md = md_path.read_text()
    for key, sym, what in SAFETY_ROWS:
        if key in res and res[key] is not None:
            assert f"| {what} | {sym} | {res[key]:.4g} |" in md
    assert all(f["source"] in md for f in res["factors"]) and md.count("\n| ") >= len(res["factors"])


def test_a_plastic_wheel_is_refused_with_the_reason():
    """wormsim.rating.plastic: a POM wheel gets no safety factor, and the reason names the standards' scope."""
    from wormsim.rating import plastic
    from wormsim.scenario import load_scenario

    res = rate(load_scenario(SCENARIOS / "seat_motor.yaml"))
    reason = plastic.refusal_reason("POM")
    assert "ISO/TS 14521" in reason and "VDI 2736" in reason
    assert res["inputs"]["wheel_material"] == "POM"  # the seat motor's wheel (seed 001)
    assert res["refused"] == plastic.refusal_reason("POM")
    assert res["safety_pitting"] is None and res["sliding_speed_m_s"] > 0
