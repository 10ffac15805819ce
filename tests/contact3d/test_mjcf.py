"""The contact3d MuJoCo model: standalone MJCF, contact filtering, collision window, guards."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tests.conftest import SCENARIOS as SCEN
from wormsim.contact3d.mjcf import build_model, write_model
from wormsim.contact3d.runner import simulate
from wormsim.contact3d.slots import repose_window
from wormsim.exceptions import SimulationError
from wormsim.physics.geometry import derive
from wormsim.scenario import load_scenario

COARSE = ["simulation.resolution=coarse"]
# the collision pieces and their window of wheel-tooth slots (contact.geometry pieces; the flank contacts have no
# collision geoms: tests/tooth/test_kernel.py)
PIECES = COARSE + ["contact.geometry=pieces"]


@pytest.fixture(scope="module")
def seat():
    return build_model(load_scenario(SCEN / "seat_motor.yaml", PIECES))


def test_only_tooth_contact_couples_the_shafts(seat):
    m = seat.model
    assert m.neq == 0 and m.ntendon == 0 and m.njnt == 2
    ct, ca = m.geom_contype, m.geom_conaffinity
    worm, wheel = seat.worm_geoms, seat.wheel_slot_geoms.ravel()
    # worm-worm and wheel-wheel never collide; worm-wheel does; visual geoms never
    assert not np.any((ct[worm][:, None] & ca[worm][None]) | (ct[worm][None] & ca[worm][:, None]))
    assert not np.any((ct[wheel][:, None] & ca[wheel][None]) | (ct[wheel][None] & ca[wheel][:, None]))
    assert np.all((ct[worm][:, None] & ca[wheel][None]) | (ct[wheel][None] & ca[worm][:, None]))
    vis = [i for i in range(m.ngeom) if i not in set(worm) | set(wheel)]
    assert np.all(ct[vis] == 0) and np.all(ca[vis] == 0)


def test_window_cost_does_not_grow_with_tooth_count():
    # the collision window, not the stiffness: Hertz's closed form keeps the FE compliance (minutes on the 120-tooth
    # wheel: test_tooth_compliance_on_a_120_tooth_wheel) out of this test
    n = []
    for z2 in (40, 120):
        over = PIECES + [f"gear.wheel_teeth={z2}", "gear.worm_length_mm=120", "contact.stiffness_model=hertz"]
        bm = build_model(load_scenario(SCEN / "involute_41.yaml", over))
        n.append((bm.window_teeth, bm.wheel_slot_geoms.size))
    assert n[0] == n[1] and n[0][1] > 0


def test_window_repose_places_the_tooth_k_pieces(seat):
    m = seat.model
    theta2 = 7.3 * 2 * math.pi / seat.geometry.z2
    ks = repose_window(seat, theta2)
    k = ks[len(ks) // 2]
    s = int(k % seat.window_teeth)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    gid = seat.wheel_slot_geoms[s, 0]
    ang = 2 * math.pi * k / seat.geometry.z2
    piece = seat.pieces.wheel_tooth_pieces[0]
    c, sn = math.cos(ang), math.sin(ang)
    want = np.array([[c, -sn, 0], [sn, c, 0], [0, 0, 1]]) @ piece.vertices.T
    # the compiled mesh is recentred: compare the hull's centre of mass
    got_centre = d.geom_xpos[gid]
    assert (
        np.linalg.norm(
            got_centre
            - piece.copy()
            .apply_transform(
                np.block([[np.array([[c, -sn, 0], [sn, c, 0], [0, 0, 1]]), np.zeros((3, 1))], [np.zeros((1, 3)), 1]])
            )
            .center_mass
        )
        < 1e-6
    )
    assert want.shape[0] == 3
    repose_window(seat, 0.0)


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack", "involute_41"])
def test_write_model_is_standalone(tmp_path, name):
    # the written MJCF is re-parsed from 6-digit numbers: the screw jack's wheel inertia once failed
    # MuJoCo's A + B >= C check there while the in-memory model compiled. The default contact.geometry (flanks): the
    # file carries the collision pieces all the same (a plain MuJoCo viewer does not run the flank contacts)
    sc = load_scenario(SCEN / f"{name}.yaml", COARSE)
    assert sc.contact.geometry == "flanks"
    path = write_model(sc, tmp_path / "m")
    m = mujoco.MjModel.from_xml_path(str(path))
    assert m.nu == 2 and m.njnt == 2 and (tmp_path / "m" / "meshes").is_dir()
    # every wheel tooth has its collision pieces, so the viewer's wheel can turn past the run's window
    z2 = sc.gear.wheel_teeth
    slots = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(m.nbody)} - {"world", "worm", "wheel"}
    assert len(slots) == z2


def test_write_model_writes_a_mesh_beyond_mujocos_stl_limit_as_obj(tmp_path, monkeypatch):
    """MuJoCo reads at most 200 000 faces from an STL file; a 77-tooth wheel's visual mesh has more (`wormsim model`
    exited 1 on it, tests/cli/test_commands_random.py): such a mesh is written as OBJ. Here the limit is lowered so that
    the screw jack's visual meshes pass it."""
    from wormsim.contact3d import mjcf

    monkeypatch.setattr(mjcf, "STL_FACES_MAX", 5000)
    path = write_model(load_scenario(SCEN / "screw_jack.yaml", COARSE), tmp_path / "m")
    objs = sorted(p.name for p in (tmp_path / "m" / "meshes").glob("*.obj"))
    assert "wheel_visual.obj" in objs and "worm_visual.obj" in objs, objs
    m = mujoco.MjModel.from_xml_path(str(path))
    assert m.nmesh == len(list((tmp_path / "m" / "meshes").iterdir()))


def test_too_large_timestep_stops_with_a_diagnosis():
    sc = load_scenario(
        SCEN / "seat_motor.yaml",
        COARSE
        + [
            "simulation.timestep_s=2e-4",
            "simulation.duration_s=0.05",
            "drive.speed_rpm=1800",
            "drive.ramp_s=0.01",
            "load.ramp_s=0.01",
        ],
    )
    with pytest.raises(SimulationError, match=r"timestep"):
        simulate(sc)


def test_self_locking_worm_creeps_under_1_percent_of_frictionless():
    """rho' = atan(0.1 / cos 10 deg) = 5.8 deg > gamma = 4.79 deg: a torque on the wheel must not turn the
    free worm; without friction the same torque spins it up."""
    base = [
        "drive.on=wheel",
        "drive.torque_nm=12",
        "drive.speed_rpm=null",
        "drive.ramp_s=0.002",
        "load.on=worm",
        "load.torque_nm=0",
        "load.ramp_s=0",
        "simulation.duration_s=0.003",
        "simulation.resolution=coarse",
        "contact.friction_static=null",
        "contact.friction_dynamic=null",
    ]
    # 3 ms: the frictionless worm reaches 54000 rpm (0.028 rad per 5e-6 s step); by 4.1 ms it turns faster than
    # contact3d resolves and the overspeed guard stops the run (docs/stability_speed.md). Measured: 0.064 rpm at mu 0.1
    speeds = {}
    for mu in (0.1, 0.0):
        res = simulate(load_scenario(SCEN / "seat_motor.yaml", base + [f"contact.friction={mu}"]))
        speeds[mu] = abs(res.series["worm_speed_rpm"][-1])
    # 10 rpm: far below the frictionless 54000 rpm of the comment above; 1 %: the creep criterion (self-locking)
    assert speeds[0.0] > 10.0
    assert speeds[0.1] < 0.01 * speeds[0.0], speeds


def test_run_writes_summary_series_report_and_3d_recording(tmp_path):
    """End to end through wormsim.run on a very short seat-motor demo: every INTERFACE.md contact3d key,
    a report and a recording holding the moving meshes, contact points and force arrows."""
    from wormsim.results.recording import recorded_entities
    from wormsim.run import run_scenario

    sc = load_scenario(SCEN / "seat_motor_demo.yaml", ["simulation.duration_s=0.03"])
    summary = run_scenario(sc, tmp_path / "out", progress=False)
    keys = [
        "ratio",
        "ratio_theory",
        "mesh_frequency_hz",
        "mesh_frequency_theory_hz",
        "tangential_force_mean_n",
        "tangential_force_p2p_n",
        "radial_force_mean_n",
        "axial_force_mean_n",
        "worm_torque_mean_nm",
        "wheel_torque_mean_nm",
        "worm_speed_mean_rpm",
        "wheel_speed_mean_rpm",
        "efficiency",
        "steady_window_s",
        "efficiency_theory",
        "timestep_s",
        "resolution",
        "contacts_mean",
    ]
    assert summary["status"] == "ok" and all(k in summary for k in keys)
    for f in ("summary.json", "timeseries.npz", "report.png", "recording.rrd"):
        assert (tmp_path / "out" / f).stat().st_size > 0
    ents = recorded_entities(tmp_path / "out" / "recording.rrd")
    for e in (
        "/assembly/worm",
        "/assembly/wheel",
        "/assembly/worm/mesh",
        "/assembly/contacts/points",
        "/assembly/contacts/forces",
        "/series/tangential_force_n",
    ):
        assert e in ents, sorted(ents)[:20]


def test_too_soft_contact_stops_on_penetration_with_a_diagnosis():
    sc = load_scenario(SCEN / "seat_motor_demo.yaml", ["contact.stiffness_n_per_m=2e5", "simulation.duration_s=0.03"])
    with pytest.raises(SimulationError, match=r"penetration .* exceeds .* raise contact.stiffness_n_per_m"):
        simulate(sc)


def test_tooth_compliance_on_a_120_tooth_wheel():
    """gmsh refuses the re-meshing of involute_41's 3-tooth sector with 120 wheel teeth at every size and feature
    angle ('Invalid boundary mesh (overlapping facets)'); the mesher's last resort, the surface as it is, meshes it."""
    from wormsim.tooth.stiffness import per_length_stiffness

    sc = load_scenario(SCEN / "involute_41.yaml", ["gear.wheel_teeth=120", "gear.worm_length_mm=120"])
    kp, src = per_length_stiffness(sc.contact, derive(sc.gear), sc.materials)
    assert src == "teeth" and kp > 0
