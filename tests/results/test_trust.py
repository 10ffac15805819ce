"""Outputs a user can trust: the meshing line (never a harmonic), the plausibility warnings, one meaning per force key
and a front door that agrees with itself. The new user's gear: 1-start ZI, z2 40, m_x 4, q 10, bronze, 1450 rpm,
150 N m (torsional runs of 0.1-0.5 s, a few seconds each)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import wormsim
from tests.conftest import ROOT
from wormsim.results import run_warnings as W
from wormsim.results.metrics import MIN_MESH_CYCLES, dominant_frequency, mesh_line, mesh_line_keys
from wormsim.results.result import Result
from wormsim.scenario import load_scenario

USER_GEAR = [
    "model=torsional",
    "gear.profile=ZI",
    "gear.worm_starts=1",
    "gear.wheel_teeth=40",
    "gear.axial_module_mm=4",
    "gear.diameter_quotient=10",
    "gear.face_width_mm=null",
    "drive.speed_rpm=1450",
    "load.torque_nm=150",
]


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    from wormsim.cli.init import write_template

    return write_template(tmp_path_factory.mktemp("trust") / "user_gear.yaml")


_RUNS: dict[tuple, dict] = {}


def user_run(template, *sets: str) -> tuple[dict, object]:
    if sets not in _RUNS:
        sc = load_scenario(template, [*USER_GEAR, *sets])
        _RUNS[sets] = (wormsim.simulate(sc).summary, sc)
    return _RUNS[sets]


# ----------------------------------------------------------------------------- 1. the meshing line


def _signal(f0: float, duration_s: float, dt: float = 1e-4):
    """A meshing signal whose 2nd harmonic is larger than its 1st (the involute_41 TE: 0.032 against 0.022 of the
    mean), with a larger contact-mode ringing at 1 kHz and noise."""
    t = np.arange(0.0, duration_s, dt)
    rng = np.random.default_rng(0)
    x = (
        100.0
        + 0.5 * np.sin(2 * np.pi * f0 * t)
        + 1.2 * np.sin(2 * np.pi * 2 * f0 * t + 0.3)
        + 0.2 * np.sin(2 * np.pi * 3 * f0 * t)
        + 3.0 * np.sin(2 * np.pi * 1000.0 * t)
        + 0.05 * rng.standard_normal(len(t))
    )
    return t, x


def test_mesh_line_is_the_fundamental_when_a_harmonic_is_larger():
    f0 = 24.1425  # z1 n1 / 60 of the user's gear at 1448.55 rpm
    t, x = _signal(f0, 0.5)
    assert abs(dominant_frequency(t, x)[0] - 1000.0) < 5  # the largest peak of the spectrum is the ringing
    line = mesh_line(t, x, f0 * 1.003)  # the theory from a measured speed 0.3 % off
    assert line["found"]
    assert abs(line["f_hz"] / f0 - 1) < 0.001, line["f_hz"]
    # the harmonics' amplitudes, 1st to 4th
    assert line["amplitudes"][:3] == pytest.approx([0.5, 1.2, 0.2], rel=0.05)
    assert line["amplitudes"][3] < 0.03


def test_mesh_line_keys_and_a_short_window_warns():
    f0 = 24.1425
    t, x = _signal(f0, 0.1)  # 2.4 mesh periods
    S = {"tangential_force_n": x, "transmission_error_rad": 1e-6 * x}
    keys = mesh_line_keys(t, S, slice(0, len(t)), f0, "tangential_force_n")
    assert keys["steady_window_mesh_cycles"] == pytest.approx(0.1 * f0, rel=0.01)
    assert keys["steady_window_mesh_cycles"] < MIN_MESH_CYCLES
    assert keys["mesh_frequency_resolution_hz"] == pytest.approx(10.0, rel=0.01)
    for k in range(1, 5):
        assert f"tangential_force_harmonic{k}_n" in keys and f"transmission_error_harmonic{k}_urad" in keys
    summary = {**keys, "mesh_frequency_theory_hz": f0, "steady_window_s": [0.0, 0.1], "power_flow": "worm to wheel"}
    (w,) = W.mesh_window_warnings(summary)
    assert "fewer than 5" in w and "simulation.duration_s" in w and "resolution 10" in w
    # a line 1 % off the theory warns; 0.1 % does not
    ok = {**summary, "steady_window_mesh_cycles": 12.0, "mesh_frequency_hz": 1.001 * f0}
    assert W.mesh_window_warnings(ok) == []
    assert "from z1 n1 / 60" in W.mesh_window_warnings({**ok, "mesh_frequency_hz": 1.01 * f0})[0]
    assert "no meshing line" in W.mesh_window_warnings({**ok, "mesh_frequency_line_found": False})[0]


def test_user_gear_torsional_meshing_line_within_half_a_percent(template):
    """torsional, 0.5 s: the TE's 2nd harmonic is larger than its 1st (measured 0.54 against 0.45 urad), the line
    24.140 Hz against z1 n1 / 60 = 24.1425 Hz; no warning."""
    s, _ = user_run(template, "simulation.duration_s=0.5")
    assert abs(s["mesh_frequency_hz"] / s["mesh_frequency_theory_hz"] - 1) <= 0.005, s["mesh_frequency_hz"]
    assert s["steady_window_mesh_cycles"] >= MIN_MESH_CYCLES
    assert s["warnings"] == []
    assert s["power_flow"] == "worm to wheel"
    assert s["transmission_error_harmonic1_urad"] > 0 and s["tangential_force_harmonic2_n"] > 0


def test_user_gear_torsional_short_window_warns(template):
    """The window of a 0.1 s run holds about one mesh period: its line is not resolved, and the run says so."""
    s, _ = user_run(template, "simulation.duration_s=0.1")
    assert s["steady_window_mesh_cycles"] < MIN_MESH_CYCLES
    assert any("mesh periods, fewer than 5" in w for w in s["warnings"]), s["warnings"]


# ----------------------------------------------------------------------------- 3. plausibility


def test_overhauling_load_reports_the_reverse_flow_efficiency(template):
    """A load that drives the wheel forward (-150 N m) against the worm's speed control: power flows from the
    wheel, efficiency = worm power out / wheel power in = tan(gamma - rho') / tan(gamma) (measured 0.5719 against
    0.5719), and the run warns."""
    s, sc = user_run(template, "simulation.duration_s=0.5", "load.torque_nm=-150")
    assert s["power_flow"] == "wheel to worm"
    from wormsim.physics.geometry import derive

    g = derive(sc.gear)
    rho = math.atan(s["friction_coefficient_mean"] / math.cos(g.alpha_n))
    assert s["efficiency"] == pytest.approx(math.tan(g.gamma - rho) / math.tan(g.gamma), rel=0.01)
    assert s["efficiency_theory"] == pytest.approx(s["efficiency"], rel=0.01)
    assert any("power flows from the wheel to the worm" in w for w in s["warnings"]), s["warnings"]


def test_contact3d_overhauling_load_takes_the_reverse_flow_theory(template):
    """contact3d, the same overhauling load (coarse, 0.12 s, Hertz stiffness: the FE compliance of a new gear apart):
    the theory keys that depend on the friction's direction follow the power flow, not the drive's shaft: the
    efficiency at the contacts' radius is tan(gamma_r - rho') / tan(gamma_r) and DIN's F_r2 takes cos(gamma - rho')
    (measured on the user's gear at 0.5 s, teeth: efficiency 0.5612 against 0.5611, F_r2 683.08 against 683.01 N;
    before, the worm-driving forms 0.6938 and 688.85 N)."""
    from wormsim.physics.geometry import derive

    s, sc = user_run(
        template,
        "model=contact3d",
        "contact.stiffness_model=hertz",
        "simulation.resolution=coarse",
        "simulation.duration_s=0.12",
        "drive.ramp_s=0.02",
        "load.ramp_s=0.02",
        "load.torque_nm=-150",
    )
    assert s["power_flow"] == "wheel to worm"
    assert s["efficiency_theory_at_contact_radius"] == pytest.approx(s["efficiency"], rel=0.01)
    g = derive(sc.gear)
    rho = math.atan(s["friction_coefficient_mean"] / math.cos(g.alpha_n))
    back = math.tan(g.alpha_n) * math.cos(rho) / math.cos(g.gamma - rho)
    assert s["radial_force_theory_n"] == pytest.approx(s["tangential_force_mean_n"] * back, rel=1e-9)
    assert s["radial_force_mean_n"] == pytest.approx(s["radial_force_theory_n"], rel=0.01)


def test_speed_zero_reports_no_ratio_and_no_efficiency(template):
    s, _ = user_run(template, "drive.speed_rpm=0")
    assert s["power_flow"] == "none"
    assert s["ratio"] is None or not math.isfinite(s["ratio"])
    assert s["efficiency"] is None or not math.isfinite(s["efficiency"])
    assert [w for w in s["warnings"] if "does not turn" in w], s["warnings"]
    assert not [w for w in s["warnings"] if "runaway" in w or "mesh periods" in w], s["warnings"]


def test_no_power_flow_while_turning_is_not_called_standing_still():
    """power_flow none while both shafts move (the held back-drive with a worm load: worm 25.8 rpm, wheel 0.102 rpm,
    measured): the warning says no power flows, not that the pair does not turn."""
    s = {"power_flow": "none", "worm_speed_mean_rpm": 25.8, "wheel_speed_mean_rpm": 0.102, "ratio_theory": 40.0}
    assert W.power_flow_warning(s, None).startswith("no power flows through the mesh")
    still = {**s, "worm_speed_mean_rpm": 1.7e-5, "wheel_speed_mean_rpm": 7e-7}
    assert W.power_flow_warning(still, None).startswith("the pair does not turn")


def test_runaway_torque_drive_warns(template):
    """A torque drive of 10 N m against the 150 N m load (T2 / (i eta) = 5.4 N m holds it): the worm accelerates
    without bound (measured 1.08e5 rpm at 0.5 s)."""
    s, _ = user_run(template, "simulation.duration_s=0.3", "drive.speed_rpm=null", "drive.torque_nm=10")
    assert any(w.startswith("runaway: the torque-driven worm still accelerates") for w in s["warnings"]), s["warnings"]


def test_contact3d_runaway_torque_drive_names_the_runaway(template):
    """contact3d stops a runaway worm at its overspeed guard (exit 3; measured on the user's gear with 10 N m: 11 609
    rpm at 0.084 s): the message says first that the torque drive exceeds what the load takes (T2 / (i eta) = 150 /
    (40 x 0.698) = 5.37 N m), not only that the timestep is too coarse for the speed."""
    from types import SimpleNamespace

    from wormsim.contact3d.diagnosis import overspeed_error
    from wormsim.physics.plan import gear_plan

    def message(torque_nm: float) -> str:
        sc = load_scenario(template, [*USER_GEAR, "drive.speed_rpm=null", f"drive.torque_nm={torque_nm}"])
        bm = SimpleNamespace(plan=SimpleNamespace(gear=gear_plan(sc)))
        return str(overspeed_error(0.084, 1216.0, 3.6e-5, bm))  # type: ignore[arg-type]

    runaway = message(10.0)
    assert runaway.startswith("runaway: the torque drive 10 N m on the worm exceeds the 5.37 N m the load takes")
    assert "worm overspeed at t = 0.084 s" in runaway
    assert message(5.0).startswith("worm overspeed")  # below the load's torque: a timestep matter only


def test_held_pair_has_no_meshing_window_warning():
    """A held self-locking pair (`locked`) creeps at a few thousandths of a mesh period over its window: no meshing line
    to resolve, so no "run N s longer" (measured on the user's gear at mu 0.12, wheel at 20 rpm, torsional: "run at
    least 6e+03 s longer")."""
    summary = {
        "steady_window_mesh_cycles": 5.4e-5,
        "mesh_frequency_theory_hz": 8.4e-4,
        "mesh_frequency_hz": None,
        "mesh_frequency_resolution_hz": 15.6,
        "steady_window_s": [0.018, 0.081],
        "power_flow": "wheel to worm",
    }
    assert "fewer than 5" in W.mesh_window_warnings(summary)[0]
    assert W.mesh_window_warnings({**summary, "locked": True}) == []


def test_a_held_back_drive_whose_worm_creeps_warns(template):
    """The user's gear at mu 0.12 (self-locking), the wheel at 20 rpm, a 3 N m load on the worm, contact3d: the
    wheel's drive stalls at its peak (7531 N m) and the run ends held, but the worm crept at 35.8 rpm (measured),
    4.5 % of the wheel command times the ratio (800 rpm): `locked` alone would read as held, so the run warns; with
    no worm load it crept at 1.7e-5 rpm (measured) and does not."""
    back = ["drive.on=wheel", "drive.speed_rpm=20", "load.on=worm", "load.torque_nm=3", "contact.friction=0.12"]
    sc = load_scenario(template, [*USER_GEAR, *back])
    held = {"locked": True, "ratio_theory": 40.0, "holding_torque_nm": 7531.0}
    w = W.creep_warning({**held, "creep_speed_rpm": 35.8}, sc)
    assert w is not None and "crept at 35.8 rpm, 4.5 % of the wheel command times the ratio (800 rpm)" in w
    assert W.creep_warning({**held, "creep_speed_rpm": 1.7e-5}, sc) is None
    assert W.creep_warning({**held, "creep_speed_rpm": 35.8, "locked": False}, sc) is None


def _result(summary, series=None):
    return Result("contact3d", summary, series or {}, 0, 0.0)


def test_runaway_speed_drive_warns_above_one_and_a_half_times_the_command(template):
    sc = load_scenario(template, USER_GEAR)
    t = np.linspace(0, 0.5, 501)
    ok = {"t_s": t, "worm_speed_rpm": np.full_like(t, 1450.0)}
    assert W.runaway_warning(_result({"steady_window_s": [0.1, 0.5]}, ok), sc) is None
    fast = {"t_s": t, "worm_speed_rpm": np.where(t > 0.3, 2500.0, 1450.0)}
    assert "above 1.5 x its command 1450 rpm" in W.runaway_warning(_result({"steady_window_s": [0.1, 0.5]}, fast), sc)


def test_contact_pressure_above_the_wheel_material_warns(template):
    """Bronze (the rating's default row for a 100 GPa wheel, CuSn12Ni2: sigma_HlimT 520 MPa): p_H max 2636 MPa (the
    user's gear at 20 000 N m) warns, 290 MPa does not."""
    sc = load_scenario(template, USER_GEAR)
    w = W.pressure_warning({"contact_pressure_max_mpa": 2636.0}, sc)
    assert w is not None and "2636 MPa" in w and "520 MPa" in w and "CuSn12Ni2" in w
    assert W.pressure_warning({"contact_pressure_max_mpa": 290.0}, sc) is None
    al = load_scenario(template, [*USER_GEAR, "rating.wheel_material=CuAl10Fe5Ni5"])
    assert W.pressure_warning({"contact_pressure_max_mpa": 600.0}, al) is None  # sigma_HlimT 660 MPa


def test_torsional_and_wedge_warn_of_a_load_above_the_wheel_materials_strength(template):
    """Load 20 000 N m on the user's gear at torsional and wedge, which compute no contact pressure: the rating's mean
    contact stress sigma_Hm (ISO/TS 14521 method B) 2320 MPa (measured) is above bronze's sigma_HlimT 520 MPa, and
    the run says so; at 150 N m (sigma_Hm 201 MPa) it does not (test_user_gear_torsional_meshing_line_within_half_a
    _percent: no warning)."""
    from wormsim.rating.rate import rate

    s, sc = user_run(template, "simulation.duration_s=0.1", "load.torque_nm=20000")
    sigma = rate(sc)["contact_stress_mean_iso_mpa"]
    assert sigma > 520.0
    (w,) = [w for w in s["warnings"] if w.startswith("the mean contact stress sigma_Hm")]
    assert f"{sigma:.4g} MPa" in w and "520 MPa (CuSn12Ni2)" in w
    wedge, _ = user_run(template, "model=wedge", "load.torque_nm=20000")
    assert any(w.startswith("the mean contact stress sigma_Hm") for w in wedge["warnings"]), wedge["warnings"]
    assert W.iso_pressure_warning({}, load_scenario(template, USER_GEAR)) is None  # 150 N m


HOLD_FROM_REST = [
    "model=contact3d",
    "gear.face_width_mm=25",
    "drive.on=wheel",
    "drive.speed_rpm=null",
    "drive.torque_nm=150",
    "load.on=worm",
    "load.torque_nm=0",
    "load.ramp_s=0",
    "simulation.duration_s=0.03",
    "contact.friction=null",
    "contact.friction_static=0.09894",  # rho' = gamma + 0.3 deg: self-locking at rest
    "contact.friction_dynamic=0.08900",  # rho' = gamma - 0.3 deg: not self-locking while sliding
]


def test_contact3d_user_gear_holds_from_rest_under_a_2_ms_load(template):
    """Static holding from rest under a fast load: the user's gear (b2 25 mm, the teeth's compliance), 150 N m on the
    wheel in 2 ms, the worm free, static friction 0.3 deg above and dynamic 0.3 deg below the locking boundary. The
    contact's elastic pre-slip passes contact.transition_velocity_m_s (1 mm/s) at 0.4 ms, but the stuck pair breaks
    away only where the friction it needs on the worm's hinge reaches mu_s times its normal forces
    (wormsim.contact3d.breakaway: 0.940 of it here, through the ramp): measured 0.0071 rpm (1.5e-6 of free), as a 20 ms
    ramp (0.0070 rpm) and constant mu_s (0.0071 rpm). Before (break-away at a slip speed of 1 mm/s): 230 rpm at 0.03 s,
    4.9 % of free (docs/decisions/0058-breakaway-on-static-friction.md)."""
    s, _ = user_run(template, *HOLD_FROM_REST, "drive.ramp_s=0.002")
    free_rpm = 4730.0  # the same run frictionless at 0.03 s (measured)
    assert s["locked"] is True and s["creep_speed_rpm"] <= 1e-3 * free_rpm, (s["locked"], s["worm_speed_mean_rpm"])


def _breakaway_torque_nm(sc) -> float:
    """The worm torque that starts the back-drive of a pair self-locking at rest, T1 = T2 / i tan(rho'_s - gamma) /
    tan(gamma), rho'_s = atan(mu_s / cos(alpha_n)) (DIN 3975: the back-driving efficiency tan(gamma - rho') /
    tan(gamma) < 0, so the worm must be pushed with that torque for the wheel's torque T2 to turn it)."""
    from wormsim.physics.geometry import derive

    g = derive(sc.gear)
    rho_s = math.atan(sc.contact.friction_static / math.cos(g.alpha_n))
    return sc.drive.torque_nm / g.ratio * math.tan(rho_s - g.gamma) / math.tan(g.gamma)


@pytest.mark.parametrize("share", [0.5, 2.0])
def test_contact3d_stuck_pair_breaks_away_where_static_friction_is_exceeded(template, share):
    """The same held pair (150 N m on the wheel in 2 ms, the worm free), then a worm torque that assists the back-drive
    (from 5 ms over 2 ms): static friction holds it below the hand formula's break-away torque (_breakaway_torque_nm,
    0.196 N m) and gives way above it. At half of it the pair holds (measured 0.0075 rpm); at twice it breaks away and
    runs back on the dynamic friction (measured 619 rpm at 0.03 s, mu 0.089). contact3d's own boundary lies between
    1.1 x (holds) and 1.4 x (runs): its contacts off the pitch point lock with 20 % more margin than the pitch-point
    formula (the hinge's need 0.940 of the static limit against tan(gamma) / tan(rho'_s) = 0.950)."""
    sc = load_scenario(template, [*USER_GEAR, *HOLD_FROM_REST, "drive.ramp_s=0.002"])
    t_nm = share * _breakaway_torque_nm(sc)
    assert 0.18 < t_nm / share < 0.21  # 3.75 N m tan(0.3 deg) / tan(5.71 deg)
    s, _ = user_run(template, *HOLD_FROM_REST, "drive.ramp_s=0.002", *_assist(t_nm))
    free_rpm = 4730.0
    if share < 1:
        assert s["locked"] is True and s["creep_speed_rpm"] <= 1e-3 * free_rpm, s["worm_speed_mean_rpm"]
    else:
        assert s["locked"] is False and s["worm_speed_mean_rpm"] > 1e-2 * free_rpm, s["worm_speed_mean_rpm"]
        assert s["friction_coefficient_mean"] == pytest.approx(sc.contact.friction_dynamic, rel=0.01)


def _assist(torque_nm: float) -> list[str]:
    """The worm's load as a torque that assists the back-drive (a negative resisting torque), from 5 ms over 2 ms."""
    return [f"load.torque_nm={-torque_nm!r}", "load.start_s=0.005", "load.ramp_s=0.002"]


# ----------------------------------------------------------------------------- 6. force keys


def test_force_keys_have_one_meaning_each():
    """The headline F_r2 and F_a2 are DIN 3975's at every level; the resultant's components are their own keys, and
    docs/outputs.md says which is which."""
    from wormsim.results.summary_keys import KEYS

    assert "radial_force_line_of_centres_mean_n" not in KEYS
    for k in ("radial_force_resultant_mean_n", "axial_force_resultant_mean_n"):
        assert KEYS[k].levels == ("contact3d",) and "resultant" in KEYS[k].meaning
    for k in ("tangential_force_mean_n", "radial_force_mean_n", "axial_force_mean_n"):
        assert (
            len(KEYS[k].levels) == 3 and "DIN 3975" in KEYS[k].meaning + (k == "tangential_force_mean_n") * "DIN 3975"
        )
    doc = (ROOT / "docs" / "outputs.md").read_text()
    section = doc.split("## Force keys", 1)[1].split("## Keys", 1)[0]
    for k in (
        "radial_force_mean_n",
        "axial_force_mean_n",
        "radial_force_resultant_mean_n",
        "axial_force_resultant_mean_n",
    ):
        assert k in section, k


# ----------------------------------------------------------------------------- 7. front door


def _docs() -> list:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def test_no_doc_cites_a_file_outside_the_repository():
    bad = re.compile(r"INTERFACE\.md|shared/|/work/|\.\./\.\./")
    hits = [f"{p.relative_to(ROOT)}: {m.group(0)}" for p in _docs() for m in bad.finditer(p.read_text())]
    assert hits == []


def test_api_md_lists_every_public_name():
    doc = (ROOT / "docs" / "api.md").read_text()
    for name in wormsim.__all__:
        assert f"`wormsim.{name}`" in doc, name


def test_scenario_md_has_every_block():
    from tools.schema_doc import BLOCKS

    doc = (ROOT / "docs" / "scenario.md").read_text()
    titles = [t for t, _ in BLOCKS]
    for block in ("shafts", "shafts.worm / shafts.wheel", "errors", "rating", "simulation", "wedge.motor"):
        assert block in titles, block
    for t in titles:
        assert f"## `{t}`" in doc, t


def test_check_prints_the_derived_sizes_timestep_and_slices(template, capsys):
    """The user's gear: d1 = q m_x = 40 mm, d2 = z2 m_x = 160 mm, a = 100 mm, b2 = 0.75 d_a1 = 36 mm; at contact3d
    the step and slices of the model its run builds (measured: 3.6e-05 s with the teeth's compliance, 0.4 x the stable
    limit 9.07e-05 s rounded down to two digits; 32 slices at medium)."""
    from wormsim.cli import main

    assert (
        main(["check", str(template), "--set", "model=contact3d", *sum((["--set", s] for s in USER_GEAR[1:]), [])]) == 0
    )
    out = capsys.readouterr().out
    derived = out.split("# derived (what the run uses):", 1)[1]
    for text in ("d1: 40 mm", "d2: 160 mm", "centre distance a: 100 mm", "face width b2: 36 mm", "worm length b1:",
                 "flank slices across the face:"):  # fmt: skip
        assert text in derived, text
    # contact3d: the step of the model its run builds (MuJoCo's opt.timestep)
    from wormsim.contact3d.mjcf import build_model

    bm = build_model(load_scenario(template, ["model=contact3d", *USER_GEAR[1:]]))
    assert f"timestep: {bm.model.opt.timestep:.3g} s" in derived
    assert f"flank slices across the face: {bm.plan.grid.slices} " in derived
    # torsional: the step the run takes
    run, _ = user_run(template, "simulation.duration_s=0.5")
    assert main(["check", str(template), *sum((["--set", s] for s in USER_GEAR[1:]), [])]) == 0
    assert f"timestep: {run['timestep_s']:.3g} s" in capsys.readouterr().out
