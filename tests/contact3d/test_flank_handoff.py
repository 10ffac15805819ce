"""The bulk hand-off of the flank contacts (wormsim.contact3d.flank_handoff) gives MuJoCo the same contacts, bit for
bit, as adding them one by one from Python (FlankContacts.add_loop), and so the same solve."""

from pathlib import Path

import mujoco
import numpy as np
import pytest

from wormsim.contact3d.flank_step import FlankContacts
from wormsim.contact3d.mjcf import build_model
from wormsim.contact3d.native import split_forward
from wormsim.scenario import load_scenario

SCEN = Path(__file__).resolve().parents[2] / "scenarios"
FIELDS = ("dist", "pos", "frame", "includemargin", "friction", "solref", "solreffriction", "solimp", "mu", "dim")
FIELDS += ("geom", "geom1", "geom2", "flex", "elem", "vert", "exclude", "efc_address")


def _compare(m, d, fc, dim, least):
    d2 = mujoco.MjData(m)
    mujoco.mj_copyData(d2, m, d)
    split_forward(m, d, fc.add)
    split_forward(m, d2, fc.add_loop)
    assert d.ncon == d2.ncon >= least
    for f in FIELDS:
        a, b = np.asarray(getattr(d.contact, f)), np.asarray(getattr(d2.contact, f))
        assert np.array_equal(a, b), f
    assert d.nefc == d2.nefc
    assert np.array_equal(d.efc_force, d2.efc_force)
    assert np.array_equal(d.qacc, d2.qacc)
    assert np.all(np.asarray(d.contact.dim) == dim)


@pytest.mark.parametrize("mode", ["slice", "tooth"])  # contact.flank_contacts (wormsim.tooth.merge)
def test_bulk_handoff_equals_python_loop(mode):
    sc = load_scenario(
        SCEN / "screw_jack.yaml",
        [
            "contact.geometry=flanks",
            "simulation.resolution=coarse",
            "drive.speed_rpm=0",
            "drive.ramp_s=0",
            "load.ramp_s=0",
            f"contact.flank_contacts={mode}",
        ],
    )
    bm = build_model(sc)
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    split_forward(m, d, fc.add)
    d.ctrl[bm.drive_actuator] = 0.0
    d.ctrl[bm.load_actuator] = -12.0
    for _ in range(1500):  # the wheel turns through the backlash and comes to rest on the worm
        fc.step(m, d)
    least = 8 if mode == "slice" else 2  # tooth: one contact per loaded flank
    assert fc.merge == (mode == "tooth")
    _compare(m, d, fc, 3, least)
    fc.set_friction(0.0)  # a new template (frictionless: dim 1) refills the records
    _compare(m, d, fc, 1, least)


def test_the_record_buffer_is_mujoco_s_own_contact_bytes():
    """wormsim.contact3d.flank_handoff.ContactBuffer: every record a copy of the template as mj_addContact stores it,
    the field offsets those of the binding's mjContact (dist first), float64-aligned."""
    from wormsim.contact3d.flank_handoff import FIELDS as WRITTEN
    from wormsim.contact3d.flank_handoff import ContactBuffer

    bm = build_model(load_scenario(SCEN / "screw_jack.yaml", ["simulation.resolution=coarse"]))
    d = mujoco.MjData(bm.model)
    t = mujoco.MjContact()
    t.dist, t.geom1, t.geom2, t.dim = -1e-6, 0, 1, 3
    t.friction = [0.1, 0.1, 0.005, 0.0001, 0.0001]
    buf = ContactBuffer(bm.model, t, cap=4)
    assert mujoco.mj_addContact(bm.model, d, t) == 0
    raw = np.frombuffer(buf.bytes[2].tobytes(), dtype=np.float64)
    c = d.contact
    assert raw[buf.off[0]] == c.dist[0]  # dist at offset 0
    for k, f in enumerate(WRITTEN, start=1):
        field = np.asarray(getattr(c, f))[0].ravel()
        assert np.array_equal(raw[buf.off[k] : buf.off[k] + field.size], field), f
    h = buf.handoff(np.array([-1.0, -2.0]), np.array([-3.0, -4.0]))
    assert h.size == buf.size and h.records.shape == (4, buf.size // 8)
