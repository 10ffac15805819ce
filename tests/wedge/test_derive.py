"""One scenario at every level: model wedge without a wedge: block derives the reduced model from gear:, drive:,
load: (wormsim.wedge.derive), with the gear levels' friction angle; what a level does not use is said."""

from __future__ import annotations

import math

import pytest

from tests.conftest import ROOT, SCENARIOS
from wormsim import cli
from wormsim.run import simulate
from wormsim.scenario import ignored_inputs, load_scenario

DEMO = SCENARIOS / "seat_motor_demo.yaml"
MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"


@pytest.fixture(scope="module")
def derived():
    return simulate(load_scenario(DEMO, ["model=wedge"])).summary


def test_derived_wedge_writes_the_common_keys_at_the_gear_theory(derived):
    s = derived
    # seat motor demo: z2 / z1 = 53 / 1; F_t2 = T2 / r2 (DIN 3975-2) with T2 = 24 N m
    assert s["ratio"] == pytest.approx(53.0, rel=1e-6)
    assert s["ratio_theory"] == 53
    assert s["tangential_force_mean_n"] == pytest.approx(s["tangential_force_theory_n"], rel=1e-6)
    # the Kloss curve through the working point: the steady speed is drive.speed_rpm at the steady friction
    assert s["worm_speed_mean_rpm"] == pytest.approx(1800.0, rel=1e-3)
    # output / input power of a rigid wedge is tan(gamma) / tan(gamma + rho') (DIN 3975-2)
    assert s["efficiency"] == pytest.approx(s["efficiency_theory"], rel=1e-4)
    assert s["power_flow"] == "worm to wheel" and s["warnings"] == []
    assert s["self_locking"] is False and 0 < s["efficiency_backdrive"] < s["efficiency"]
    assert s["wedge_source"].startswith("derived")


def test_one_friction_input_gives_one_friction_angle_at_wedge_and_torsional(derived):
    tors = simulate(load_scenario(DEMO, ["model=torsional", "simulation.duration_s=0.05"])).summary
    # contact friction_dynamic 0.05, alpha_n 10 deg: rho' = atan(0.05 / cos 10 deg) (DIN 3975-2)
    rho = math.degrees(math.atan(0.05 / math.cos(math.radians(10))))
    assert derived["friction_angle_dynamic_deg"] == pytest.approx(rho, rel=1e-9)
    assert tors["friction_angle_dynamic_deg"] == pytest.approx(rho, rel=1e-9)
    # static: friction_static 0.08 at rest
    assert derived["friction_angle_static_deg"] == pytest.approx(tors["friction_angle_static_deg"], rel=1e-12)
    for key in ("tangential_force_mean_n", "radial_force_mean_n", "axial_force_mean_n", "efficiency_theory"):
        assert derived[key] == pytest.approx(tors[key], rel=2e-3), key


def test_a_self_locking_gear_locks_at_the_derived_wedge():
    # q = 20, one start: gamma = atan(1 / 20) = 2.86 deg < rho' = atan(0.08 / cos 20 deg) = 4.87 deg
    s = simulate(load_scenario(MINIMAL, ["model=wedge", "gear.diameter_quotient=20", "contact.friction=0.08"])).summary
    assert s["self_locking"] is True and s["self_locking_dynamic"] is True and s["efficiency_backdrive"] == 0.0


def test_wedge_block_beside_gear_blocks_says_they_are_ignored(tmp_path, capsys):
    sets = ["gear.wheel_teeth=30", "gear.axial_module_mm=2", "gear.diameter_quotient=10"]
    sc = load_scenario(SCENARIOS / "mov_1.yaml", sets)
    assert any(line.startswith("gear: ignored") for line in ignored_inputs(sc))
    argv = ["run", str(SCENARIOS / "mov_1.yaml"), "--out", str(tmp_path), "--no-progress"]
    assert cli.main(argv + [x for s in sets for x in ("--set", s)]) == 0
    assert "gear: ignored: the wedge: block gives the whole reduced model" in capsys.readouterr().err


def test_gear_levels_say_a_wedge_block_is_ignored():
    sc = load_scenario(MINIMAL, ["model=torsional", "wedge.lead_angle_deg=5"])
    assert ignored_inputs(sc) == ["wedge: ignored: model torsional uses gear:, drive:, load:"]


@pytest.mark.parametrize(
    "sets, names",
    [
        (["drive.speed_rpm=null", "drive.torque_nm=1"], "drive.torque_nm = 1"),
        (["drive.on=wheel", "load.on=worm"], "drive.on = wheel"),
    ],
)
def test_derived_wedge_refuses_a_drive_it_cannot_model(tmp_path, capsys, sets, names):
    argv = ["run", str(MINIMAL), "--out", str(tmp_path), "--set", "model=wedge"]
    assert cli.main(argv + [x for s in sets for x in ("--set", s)]) == 2
    err = capsys.readouterr().err
    assert names in err and "allowed: drive.on worm with drive.speed_rpm > 0" in err


def test_an_assisting_load_is_held_at_the_drive_speed_by_a_braking_motor():
    s = simulate(load_scenario(DEMO, ["model=wedge", "load.torque_nm=-5"])).summary
    # drive.speed_rpm 1800 of scenarios/seat_motor_demo.yaml: the braking motor holds the commanded speed
    assert s["worm_speed_mean_rpm"] == pytest.approx(1800.0, rel=1e-3)
    assert s["regimes"][-1] == "inverse"
    # the worm brakes with F_t1 = F_t2 tan(gamma - rho') (DIN 3975-2, back-driving), rho' = atan(0.05 / cos 10 deg)
    g, rho = math.radians(s["lead_angle_deg"]), math.radians(s["friction_angle_dynamic_deg"])
    assert s["S1_steady_n"] == pytest.approx(-s["tangential_force_mean_n"] * math.tan(g - rho), rel=1e-4)
    # the load overhauls the drive (issue 31): power flows from the wheel, the efficiency is the worm's power out
    # over the wheel's in, tan(gamma - rho') / tan(gamma) (DIN 3975-2) for a rigid wedge, not null; the run warns
    assert s["power_flow"] == "wheel to worm"
    assert s["efficiency"] == pytest.approx(math.tan(g - rho) / math.tan(g), rel=1e-4)
    assert s["efficiency_theory"] == pytest.approx(math.tan(g - rho) / math.tan(g), rel=1e-9)
    assert any(w.startswith("power flows from the wheel to the worm") for w in s["warnings"]), s["warnings"]


@pytest.mark.parametrize(
    "model, sets, line",
    [
        (
            "torsional",
            ["contact.slices=16", "simulation.resolution=fine"],
            "contact.slices, simulation.resolution ignored: used by model contact3d only",
        ),
        ("contact3d", ["simulation.mesh_stiffness_samples=32"], "simulation.mesh_stiffness_samples ignored"),
        ("wedge", ["contact.slices=16"], "contact.slices ignored: the wedge is rigid and without backlash"),
    ],
)
def test_keys_a_level_does_not_use_are_named(model, sets, line):
    lines = ignored_inputs(load_scenario(MINIMAL, [f"model={model}", *sets]))
    assert any(x.startswith(line) for x in lines), lines
    assert len(lines) == 1, lines
