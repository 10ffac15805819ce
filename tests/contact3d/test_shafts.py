"""shafts: the worm and the wheel on compliant bearings, the worm shaft bending (wormsim.contact3d.shafts).

Expected numbers and their sources: the beam stiffness 3 E I L / (l1^2 l2^2) (48 E I / L^3 midway; Roark's Formulas
for Stress and Strain, table 8.1 case 1e), I = pi d^4 / 64; static equilibrium of a shaft (the bearing forces balance
the mesh force; the locating bearing takes the worm's axial force, which is the wheel's tangential force, DIN 3975);
the 3 % tolerances are issue 25's acceptance criteria. The screw jack at 8 slices and 0.08 s keeps the runs cheap
(steady window from 0.055 s, after the 0.05 s ramps)."""

from __future__ import annotations

import functools
import json
import math
from pathlib import Path

import numpy as np
import pytest

from meshgen import assembly
from wormsim.cli.check import level_lines
from wormsim.contact3d import shafts
from wormsim.contact3d.mass_scaling import floor_2_digits
from wormsim.contact3d.mjcf import build_model
from wormsim.contact3d.timestep import SHAFTS_SOURCE
from wormsim.physics.geometry import derive
from wormsim.run import simulate
from wormsim.scenario import Scenario, ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[2]


def _scenario(shafts_block: dict | None, torque_nm: float = 12.0) -> Scenario:
    d = load_scenario(ROOT / "scenarios/screw_jack.yaml").model_dump()
    d["simulation"]["duration_s"] = 0.08
    d["contact"]["slices"] = 8
    d["load"]["torque_nm"] = torque_nm
    if shafts_block is not None:
        d["shafts"] = shafts_block
    return Scenario.model_validate(d)


@functools.lru_cache(maxsize=8)
def _run(block_json: str, torque_nm: float = 12.0):
    r = simulate(_scenario(json.loads(block_json), torque_nm))
    return r.summary, r.series


def _bent(span_mm: float = 60.0) -> str:
    return json.dumps({"worm": {"bearings_mm": [-span_mm, span_mm], "bending": True}})


def test_beam_stiffness_formula():
    E, d, L = 210e9, 0.02, 0.12
    I = math.pi * d**4 / 64
    assert shafts.root_second_moment_m4(d) == pytest.approx(I, rel=1e-15)
    assert shafts.beam_stiffness_n_per_m(E, I, L / 2, L / 2) == pytest.approx(48 * E * I / L**3, rel=1e-12)
    # off-centre: the deflection under the load F a^2 b^2 / (3 E I L)
    assert 1 / shafts.beam_stiffness_n_per_m(E, I, 0.03, 0.09) == pytest.approx(
        0.03**2 * 0.09**2 / (3 * E * I * 0.12), rel=1e-12
    )


RIGID = json.dumps({"worm": {"bearings_mm": [-60, 60]}, "wheel": {"bearings_mm": [-30, 30]}})


def test_absent_block_builds_todays_model_and_rigid_shafts_reproduce_it():
    bm = build_model(_scenario(None))
    assert "shafts" not in bm.meta and "poses_from_data" not in bm.meta  # the rigid hinges' path, untouched
    assert bm.model.njnt == 2
    base, _ = _run("null")
    rigid, _ = _run(RIGID)
    # 0.0: rigid shafts (no bending joint) deflect by construction
    assert rigid["worm_deflection_mesh_um"] == 0.0 and rigid["wheel_deflection_mesh_um"] == 0.0
    for k in ("ratio", "tangential_force_mean_n", "radial_force_mean_n", "axial_force_mean_n", "efficiency"):
        assert rigid[k] == pytest.approx(base[k], rel=1e-9), k


def test_worm_bending_against_the_beam_formula_load_and_span():
    s, _ = _run(_bent(60.0))
    sc = _scenario(json.loads(_bent(60.0)))
    geo = derive(sc.gear)
    k_b = shafts.beam_stiffness_n_per_m(210e9, shafts.root_second_moment_m4(2 * geo.r_f1), 0.06, 0.06)
    # the mesh force across the worm axis: the wheel's radial and axial components (the worm axis is the wheel's
    # tangential direction)
    f_perp = math.hypot(s["radial_force_resultant_mean_n"], s["axial_force_resultant_mean_n"])
    assert s["worm_deflection_mesh_um"] == pytest.approx(1e6 * f_perp / k_b, rel=0.02)
    half, _ = _run(_bent(60.0), 6.0)
    # linear beam: deflection ~ load, 12 N m / 6 N m = 2
    assert s["worm_deflection_mesh_um"] / half["worm_deflection_mesh_um"] == pytest.approx(2.0, rel=0.03)
    short, _ = _run(_bent(30.0))
    # center-loaded beam k = 48 E I / L^3: deflection ~ L^3, (120 / 60)^3 = 8
    assert s["worm_deflection_mesh_um"] / short["worm_deflection_mesh_um"] == pytest.approx(8.0, rel=0.03)


def test_bearing_forces_balance_the_mesh_forces():
    from wormsim.bench.cases import SHAFTS_BLOCK  # both shafts compliant, the worm bending (the bench's twin)

    s, S = _run(json.dumps(SHAFTS_BLOCK))
    r, R = _run(RIGID)  # rigid bearings: their forces are the constraint's reaction split by the statics
    for summ, series in ((s, S), (r, R)):
        _balance(summ, series)
    assert len(s["worm_bearing_radial_mean_n"]) == 2 and len(s["wheel_bearing_radial_max_n"]) == 2
    # the wheel shaft on two radial springs (500 N/um each) at +-30 mm, the mesh in the middle: statics give each
    # bearing half the mesh force across the axis, so the axis moves at the mesh point by |F_t2, F_r2| / (2 k)
    # (a rigid shaft on springs; the axial force's moment tilts it about the mid-plane, which leaves the mesh point)
    # (the resultant radial force of the contacts: the force that loads the wheel shaft; radial_force_mean_n is DIN
    # 3975's F_r2 on the line of centres, docs/outputs.md "Force keys")
    f_across = math.hypot(s["tangential_force_mean_n"], s["radial_force_resultant_mean_n"])
    # (measured 0.42209 um against 0.42209 um; 1e-3 leaves room for the mean of a magnitude against a magnitude of
    # means)
    assert s["wheel_deflection_mesh_um"] == pytest.approx(1e6 * f_across / (2 * 500e6), rel=1e-3)
    # a two-bearing shaft is statically determinate: the split over the bearings does not depend on their stiffness
    # (the mesh forces themselves move a little with the compliance: radial +0.8 %, wheel axial -15 % here)
    for part in ("worm", "wheel"):
        total = sum(r[f"{part}_bearing_radial_mean_n"])
        for rigid_n, spring_n in zip(r[f"{part}_bearing_radial_mean_n"], s[f"{part}_bearing_radial_mean_n"]):
            assert abs(rigid_n - spring_n) < 0.02 * total, (part, r[f"{part}_bearing_radial_mean_n"])


def _balance(s: dict, S: dict) -> None:
    """The bearings' forces on each shaft balance the mesh force on it; the locating bearings take the axial
    forces (the worm's: the wheel's tangential force)."""
    t = S["t_s"]
    sl = (t >= s["steady_window_s"][0]) & (t <= s["steady_window_s"][1])

    def mean(key: str) -> float:
        return float(np.mean(S[key][sl]))

    # the force on the wheel in the assembly frame from the series' signs (docs/outputs.md: tangential +x, radial
    # positive towards the wheel axis = +y, axial along -hand z; a right-hand worm here)
    hand = 1.0
    F = np.array([mean("tangential_force_n"), mean("radial_force_n"), -hand * mean("axial_force_n")])
    assert s["worm_bearing_axial_mean_n"] == pytest.approx(s["tangential_force_mean_n"], rel=0.03)
    assert s["wheel_bearing_axial_mean_n"] == pytest.approx(s["axial_force_resultant_mean_n"], rel=0.03)
    # worm: the bearings' forces on the shaft balance the mesh force on the worm (-F) across its axis (worm frame)
    f_worm = assembly.R0.T @ -F
    bear = np.array([sum(mean(f"worm_bearing{i}_radial_{a}_n") for i in range(2)) for a in "xy"])
    assert np.linalg.norm(bear + f_worm[:2]) < 0.03 * np.linalg.norm(f_worm[:2])
    bear = np.array([sum(mean(f"wheel_bearing{i}_radial_{a}_n") for i in range(2)) for a in "xy"])
    assert np.linalg.norm(bear + F[:2]) < 0.03 * np.linalg.norm(F[:2])


def test_bad_shafts_input_names_the_field():
    with pytest.raises(ValueError, match=r"bearings_mm\[0\] < 0 < bearings_mm\[1\]"):
        _scenario({"worm": {"bearings_mm": [10, 60]}})
    with pytest.raises(ValueError, match="shafts.wheel.bending"):
        _scenario({"wheel": {"bearings_mm": [-10, 60], "bending": True}})
    with pytest.raises(ValueError, match="simulation.mass_scaling"):
        Scenario.model_validate(
            {
                **_scenario(None).model_dump(),
                "shafts": {"worm": {"bearings_mm": [-9, 9]}},
                "simulation": {"duration_s": 1, "mass_scaling": 10},
            }
        )
    stiff = {"worm": {"bearings_mm": [-60, 60], "radial_stiffness_n_per_um": 1e6}}
    given = Scenario.model_validate(
        {**_scenario(stiff).model_dump(), "simulation": {"duration_s": 0.08, "timestep_s": 1e-5}}
    )
    with pytest.raises(ScenarioError, match="simulation.timestep_s"):
        build_model(given)


def test_default_step_follows_the_shafts_stiffest_mode():
    """Without simulation.timestep_s a shaft mode stiffer than the contact lowers the default to 0.4 x its explicit
    limit, rounded down to two digits (the contact's rule, wormsim.contact3d.timestep); the contact's own default holds
    otherwise."""
    stiff = build_model(_scenario({"worm": {"bearings_mm": [-60, 60], "radial_stiffness_n_per_um": 1e6}}))
    lim = shafts.stable_limit_s(stiff.model)
    assert stiff.timestep_source == SHAFTS_SOURCE
    assert stiff.model.opt.timestep == floor_2_digits(0.4 * lim) < 0.4 * stiff.law.stable_limit_s
    printed = level_lines(_scenario({"worm": {"bearings_mm": [-60, 60], "radial_stiffness_n_per_um": 1e6}}))[0]
    assert printed.startswith(f"timestep: {stiff.model.opt.timestep:.3g} s ({SHAFTS_SOURCE})")  # wormsim check
    soft = build_model(_scenario({"worm": {"bearings_mm": [-60, 60]}}))
    assert soft.timestep_source != SHAFTS_SOURCE and soft.model.opt.timestep <= 0.4 * shafts.stable_limit_s(soft.model)


@pytest.mark.parametrize("block", [RIGID, json.dumps({"worm": {"bearings_mm": [-60, 60], "bending": True}})])
def test_shaft_log_series_equal_the_per_sample_formulas(block):
    """ShaftLog's raw rows and its series after the loop against the outputs computed from mjData at each sample
    (the constraint reaction of the outermost shaft body about the mesh point, in the shaft frame, split by the
    statics; the deflections from the joints): bit for bit, up to a few ulps where numpy's matrix products round."""
    import mujoco

    from wormsim.contact3d.flank_step import FlankContacts
    from wormsim.contact3d.native import split_forward
    from wormsim.physics import gear_theory as gt

    sc = _scenario(json.loads(block))
    sc.drive.ramp_s, sc.load.ramp_s = 0.001, 0.001  # loaded within the samples
    bm = build_model(sc)
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    split_forward(m, d, fc.add)
    cmds = gt.duty(sc, bm.direction).commands
    n, every = 12, 25
    log = shafts.ShaftLog(m, bm.meta["shafts"], n)
    ref: dict[str, list[float]] = {}
    for i in range(n):
        for j in range(every):
            t = np.array([(i * every + j + 0.5) * m.opt.timestep])
            d.ctrl[bm.drive_actuator], d.ctrl[bm.load_actuator] = cmds.drive(t)[0], cmds.load(t)[0]
            fc.step(m, d)
        log.record(i, d)
        for k, v in _per_sample(m, d, log).items():
            ref.setdefault(k, []).append(v)
    S = log.series()
    assert S.keys() == ref.keys()
    assert max(np.hypot(ref["worm_bearing1_radial_x_n"], ref["worm_bearing1_radial_y_n"])) > 10.0  # loaded
    for k, v in ref.items():
        scale = max(np.abs(v).max(), 1e-300)
        assert np.abs(S[k] - np.array(v)).max() <= 4 * np.finfo(float).eps * scale, k


def _per_sample(m, d, log: shafts.ShaftLog) -> dict[str, float]:
    """The shafts' outputs at this instant from mjData (ShaftLog's docstring), one sample."""
    import mujoco

    if log.reactions:
        mujoco.mj_rnePostConstraint(m, d)
    out = {}
    for part, ids in log.parts.items():
        sup = log.supports[part]
        field = {c: k for c, (_, k) in enumerate(log.cols)}  # raw column -> flat index in its field
        q = d.qpos
        a = ids["defl"]
        out[f"{part}_deflection_mesh_x_m"] = 0.0 + sum(q[field[c]] for c in (a[0], a[2]) if c >= 0)
        out[f"{part}_deflection_mesh_y_m"] = 0.0 + sum(q[field[c]] for c in (a[1], a[3]) if c >= 0)
        if ids["rigid"]:
            b = field[ids["xpos"][0]] // 3
            torque, force = d.cfrc_int[b, :3], d.cfrc_int[b, 3:]
            moment = torque + np.cross(d.subtree_com[m.body_rootid[b]] - d.xpos[b], force)
            R = d.xmat[b].reshape(3, 3)
            if ids["hinge"] >= 0:
                th = float(q[field[ids["hinge"]]])
                R = R @ np.array([[math.cos(th), math.sin(th), 0.0], [-math.sin(th), math.cos(th), 0.0], [0, 0, 1.0]])
            f_loc, m_loc = R.T @ force, R.T @ moment
            split = shafts.bearing_split(f_loc, m_loc, sup.bearings_m)
        for bb in range(2):
            for ax in range(2):
                key = f"{part}_bearing{bb}_radial_{'xy'[ax]}_n"
                if ids["tendons"][0][0] >= 0:
                    out[key] = -sup.radial_n_per_m * d.ten_length[field[ids["tendons"][bb][ax]]]
                else:
                    out[key] = float(split[bb][ax])
        if ids["axial"] >= 0:
            out[f"{part}_bearing_axial_n"] = -sup.axial_n_per_m * q[field[ids["axial"]]]
        else:
            out[f"{part}_bearing_axial_n"] = float(f_loc[2])
    return out
