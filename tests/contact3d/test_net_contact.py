"""The contact sensor computed in the compiled loop (wormsim.contact3d.net_contact) against MuJoCo's own
(mj_sensorAcc), bit for bit: on a flank run with friction and without (cones of dimension 3 and 1), and on boxes on a
plane whose contacts come the other way round (the flipped direction)."""

from pathlib import Path

import mujoco
import numpy as np
import pytest

from wormsim.contact3d import mjcf, native
from wormsim.contact3d.flank_step import FlankContacts
from wormsim.contact3d.net_contact import DATA, SIZE, contact_offsets, geom_match, net_contact, sensor_id
from wormsim.scenario import load_scenario

SCEN = Path(__file__).resolve().parents[2] / "scenarios"
BASE = ["contact.geometry=flanks", "simulation.resolution=coarse", "drive.ramp_s=0.002", "load.ramp_s=0.002"]

BOXES = """<mujoco><option timestep="2e-3" cone="elliptic"/>
<worldbody><geom name="floor" type="plane" size="2 2 .1"/>
<body name="a" pos="0 0 .098"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
<body name="b" pos=".35 0 .099" euler="0 0 20"><freejoint/><geom type="box" size=".08 .08 .1"/></body>
</worldbody><sensor><contact body1="a" body2="world" reduce="netforce" data="found force torque pos"/></sensor>
</mujoco>"""


def _check(m, d, sid) -> np.ndarray:
    out, w = np.zeros(SIZE), np.zeros(6)
    base = np.asarray(d.contact.dist).ctypes.data if d.ncon else 0
    net_contact(base, d.ncon, contact_offsets(), d.efc_force, geom_match(m, sid), out, w)
    adr = m.sensor_adr[sid]
    return out - d.sensordata[adr : adr + SIZE], out


def test_mesh_sensor_is_the_layout_net_contact_writes():
    assert mjcf.MESH_SENSOR_DATA == DATA


@pytest.mark.parametrize("mu", [0.05, 0.0])
def test_flank_run_sensor_bit_for_bit(mu):
    bm = mjcf.build_model(load_scenario(SCEN / "screw_jack.yaml", BASE))
    m = bm.model
    d = mujoco.MjData(m)
    sid = sensor_id(m, int(m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "mesh_force")]))
    assert sid >= 0
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    native.split_forward(m, d, fc.add)
    fc.set_friction(mu)
    dt = m.opt.timestep
    t = (np.arange(300) + 0.5) * dt
    cmd, load = bm.plan.commands.drive(t), bm.plan.commands.load(t)
    touching = 0
    for j in range(len(t)):
        d.ctrl[bm.drive_actuator], d.ctrl[bm.load_actuator] = cmd[j], load[j]
        fc.step(m, d)
        diff, out = _check(m, d, sid)
        assert np.array_equal(diff, np.zeros(SIZE)), (j, diff)
        touching += out[0] > 0
    assert touching > 100 and abs(d.sensordata[m.sensor_adr[sid] + 1]) > 0.0
    assert (d.contact.dim[: d.ncon] == (3 if mu > 0 else 1)).all()


def test_flipped_contacts_bit_for_bit():
    m = mujoco.MjModel.from_xml_string(BOXES)
    d = mujoco.MjData(m)
    d.qvel[0] = 0.3
    sid = sensor_id(m, 0)
    assert sid == 0
    for j in range(100):
        mujoco.mj_step(m, d)
        diff, out = _check(m, d, sid)
        assert np.array_equal(diff, np.zeros(SIZE)), (j, diff)
    assert d.ncon >= 4 and out[0] == 4  # box a's four corners on the floor, flipped (the floor is geom 1)
    # flipped: the floor is each contact's geom 1, its normal points up into box a; the sensor's force, negated, down
    assert d.contact.geom[0][0] == 0 and out[3] < 0.0
