"""The compiled step loop (wormsim.contact3d.flank_loop) steps the model exactly as the Python split step
(FlankContacts.step) with the runner's per-step sums: same qpos, qvel, efc_force and sums, bit for bit."""

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from wormsim.contact3d.contact_sums import RadiusLog
from wormsim.contact3d.flank_loop import FlankLoop
from wormsim.contact3d.flank_step import FlankContacts
from wormsim.contact3d.mjcf import build_model
from wormsim.contact3d.native import split_forward, split_step
from wormsim.scenario import load_scenario

SCEN = Path(__file__).resolve().parents[2] / "scenarios"
N_STEPS = 400
BASE = ["contact.geometry=flanks", "simulation.resolution=coarse", "drive.ramp_s=0.002", "load.ramp_s=0.002"]


def _python_sums(m, d, fc, bm, cmd, load, a1, a2, s0):
    """The runner's former per-step loop (wormsim.contact3d.runner.run_model before flank_loop), the step from Python
    (native.split_step with FlankContacts.add); the drive's command under its peak torque
    (wormsim.physics.gear_theory.servo_command; the screw jack's worm drives)."""
    from wormsim.physics import gear_theory as gt

    sd, act, qv, ctrl = d.sensordata, d.actuator_force, d.qvel, d.ctrl
    band = bm.plan.servo_band_rad_s
    t1 = t2 = p1 = p2 = nc = fx = fy = fz = mz = fpk = 0.0
    for j in range(len(cmd)):
        ctrl[bm.drive_actuator] = gt.servo_command(float(cmd[j]), float(qv[bm.worm_dof]), band)
        ctrl[bm.load_actuator] = load[j]
        w1j, w2j = qv[bm.worm_dof], qv[bm.wheel_dof]
        split_step(m, d, fc.add)
        q1, q2 = act[a1], act[a2]
        t1 += q1
        t2 += q2
        p1 += q1 * w1j
        p2 += q2 * w2j
        nc += sd[s0]
        f0, f1, f2 = sd[s0 + 1], sd[s0 + 2], sd[s0 + 3]
        fx += f0
        fpk = max(fpk, abs(f0))
        fy += f1
        fz += f2
        mz += sd[s0 + 6] + sd[s0 + 7] * f1 - sd[s0 + 8] * f0
    return np.array([t1, t2, p1, p2, nc, fx, fy, fz, mz, fpk])


MODES = ["slice", "tooth"]  # contact.flank_contacts: one MuJoCo contact per slice, or per tooth flank (flank_merge)


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("sets", [[], ["errors.shaft_angle_deg=0.1", "errors.worm_runout_mm=0.01"]])
def test_compiled_loop_equals_python_split_step(sets, mode):
    sc = load_scenario(SCEN / "screw_jack.yaml", BASE + sets + [f"contact.flank_contacts={mode}"])
    bm = build_model(sc)
    m = bm.model
    from wormsim.physics import gear_theory as gt

    dt = m.opt.timestep
    cmds = gt.duty(sc, bm.direction).commands
    t = (np.arange(N_STEPS) + 0.5) * dt
    cmd, load = cmds.drive(t), cmds.load(t)
    a1, a2 = (bm.drive_actuator, bm.load_actuator)  # the screw jack's worm drives
    s0 = int(m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "mesh_force")])

    d_py, d_nb = mujoco.MjData(m), mujoco.MjData(m)
    fc_py = FlankContacts(bm, bm.law.contacts_per_pair)
    fc_nb = FlankContacts(bm, bm.law.contacts_per_pair)
    assert fc_nb.displaced == bool(sets)
    assert fc_nb.merge == (mode == "tooth")
    split_forward(m, d_py, fc_py.add)
    split_forward(m, d_nb, fc_nb.add)
    loop = FlankLoop(fc_nb, d_nb, bm.drive_actuator, bm.load_actuator, a1, a2, s0)

    rec = 7  # record intervals of 7 steps; the sums compared per interval
    most = 0
    for j0 in range(0, N_STEPS - rec + 1, rec):
        ref = _python_sums(m, d_py, fc_py, bm, cmd[j0 : j0 + rec], load[j0 : j0 + rec], a1, a2, s0)
        got = loop.run(cmd, load, j0, j0 + rec).copy()
        assert np.array_equal(got, ref), (j0, got - ref)
        assert fc_nb.n == fc_py.n
        most = max(most, fc_nb.n)
        mu = 0.05 + 0.04 * math.sin(j0)  # the runner changes friction between intervals
        fc_py.set_friction(mu)
        fc_nb.set_friction(mu)
    assert most > 1 and d_nb.ncon == d_py.ncon > 0
    assert (d_nb.ncon < fc_nb.n) == (mode == "tooth")  # merged: fewer MuJoCo contacts than slice contacts
    assert np.array_equal(d_nb.qpos, d_py.qpos)
    assert np.array_equal(d_nb.qvel, d_py.qvel)
    assert d_nb.nefc == d_py.nefc
    assert np.array_equal(d_nb.efc_force, d_py.efc_force)
    assert np.array_equal(fc_nb.ks, fc_py.ks) and fc_nb.centre == fc_py.centre
    assert loop.dropped == 0


ERRORS = ["errors.center_distance_mm=0.02", "errors.worm_runout_mm=0.01", "errors.wheel_axial_offset_mm=0.02"]


def _numpy_points_tooth0(P: np.ndarray, meta: np.ndarray, pw: np.ndarray, z2: int) -> np.ndarray:
    """Points in tooth 0's frame via the displaced wheel body (wormsim.tooth.pose) in numpy: X_g^-1 w, then turned by
    -(2 pi k / z2 + f_k / r2) about z."""
    from wormsim.tooth.pose import SHIFT, WHEEL

    X = P[WHEEL : WHEEL + 12].reshape(3, 4)
    pb = (pw - X[:, 3]) @ X[:, :3]
    ks = meta[:, 0]
    ang = -(2 * math.pi * ks / z2 + P[SHIFT + np.mod(ks.astype(np.int64), len(P) - SHIFT)])
    c, s = np.cos(ang), np.sin(ang)
    return np.stack([c * pb[:, 0] - s * pb[:, 1], s * pb[:, 0] + c * pb[:, 1], pb[:, 2]], axis=1)


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("sets", [[], ERRORS], ids=["rigid", "errors"])
def test_compiled_sample_equals_numpy_path(mode, sets):
    """FlankLoop.sample against flank_contact_details, PatternLog.record and the numpy sums the runner used; with
    assembly errors its points in tooth 0's frame against the displaced wheel body's frame in numpy (a few ulps:
    numpy's matrix product and cos may round differently)."""
    from wormsim.contact3d.flank_step import flank_contact_details
    from wormsim.physics import gear_theory as gt
    from wormsim.tooth.hertz import PatternLog

    sc = load_scenario(SCEN / "screw_jack.yaml", BASE + sets + [f"contact.flank_contacts={mode}"])
    bm = build_model(sc)
    m, geo = bm.model, bm.geometry
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    split_forward(m, d, fc.add)
    loop = FlankLoop(fc, d, bm.drive_actuator, bm.load_actuator, bm.drive_actuator, bm.load_actuator, 0)
    t = (np.arange(N_STEPS) + 0.5) * m.opt.timestep
    cmds = gt.duty(sc, bm.direction).commands
    loop.run(cmds.drive(t), cmds.load(t), 0, N_STEPS)
    assert fc.n > 4
    mu = 0.05
    ref_log, log = PatternLog(fc, 2.2e11), PatternLog(fc, 2.2e11)
    assert fc.displaced == bool(sets)
    nteeth, pen, p0, F, pw = flank_contact_details(fc, d)
    if sets:
        n = fc.n if fc.merge else min(fc.n, d.ncon)
        ref = _numpy_points_tooth0(fc.params, fc.meta[:n][np.asarray(fc.slice_rows(d)[0]) >= 0], pw, geo.z2)
        scale = np.abs(ref).max()
        assert np.abs(p0 - ref).max() <= 8 * np.finfo(float).eps * scale, np.abs(p0 - ref).max() / scale
    ref_log.record(3, d)
    store = tuple(np.full((5, 4, 3), np.nan, dtype=np.float32) for _ in range(3))
    rlog = RadiusLog()
    got = loop.sample(3, log, rlog, store)
    assert got[:2] == (nteeth, pen)
    for a, b in zip(store, (p0, F, pw)):
        assert np.array_equal(a[3], b[:4].astype(np.float32))
        assert np.isnan(a[:3]).all() and np.isnan(a[4]).all()
    assert log.m == ref_log.m > 0 and np.array_equal(log.buf[: log.m], ref_log.buf[: ref_log.m])
    # the numpy sums the runner used per sample
    phi = np.arctan2(pw[:, 2], pw[:, 1] + geo.a)
    fr_lc = float(-(F[:, 1] * np.cos(phi) + F[:, 2] * np.sin(phi)).sum())
    w = np.linalg.norm(F, axis=1)
    r = np.hypot(pw[:, 1] + geo.a, pw[:, 2])
    eta = gt.efficiency_at_radius(geo.gamma, geo.r1, r, mu, geo.alpha_n)
    assert np.allclose(got[2:], (fr_lc, (w * r).sum() / w.sum()), rtol=1e-12, atol=0)
    eta_c = rlog.efficiency(np.full(5, mu), geo, True)
    assert np.isnan(eta_c[[0, 1, 2, 4]]).all()
    assert eta_c[3] == pytest.approx((w * eta).sum() / w.sum(), rel=1e-12)
