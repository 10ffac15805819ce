"""MuJoCo's native side (wormsim.contact3d.native): each stage list against MuJoCo's own functions, as MJX tests its
stages against MuJoCo C. split_forward against mj_forward, split_step and the compiled stage list (by address, as the
flank loop calls it) against mj_step, for the Euler and the implicitfast integrator, bit for bit; and contacts added
in the ADD_CONTACTS slot enter the solver exactly as MuJoCo's own collision's contacts."""

from __future__ import annotations

import re

import mujoco
import numba
import numpy as np
import pytest

from wormsim.contact3d import native

# two boxes on a plane (free joints: contacts, constraint rows, friction), a hinge with a motor and a sensor per stage
XML = """<mujoco><option timestep="2e-3" integrator="{integrator}" cone="elliptic"/>
<worldbody><geom name="floor" type="plane" size="2 2 .1" {floor}/>
<body name="a" pos="0 0 .098"><freejoint/><geom type="box" size=".1 .1 .1" {box}/>
<site name="s" pos=".1 0 0"/></body>
<body name="b" pos=".35 0 .099" euler="0 0 20"><freejoint/><geom type="box" size=".08 .08 .1" {box}/></body>
<body name="arm" pos="0 1 .5"><joint name="h" type="hinge" axis="0 1 0" damping=".1"/>
<geom type="capsule" fromto="0 0 0 .3 0 0" size=".02"/></body></worldbody>
<actuator><motor joint="h" gear="2"/></actuator>
<sensor><framepos objtype="site" objname="s"/><jointvel joint="h"/><accelerometer site="s"/>
<touch site="s"/></sensor></mujoco>"""
INTEGRATORS = ("Euler", "implicitfast")  # the ones the project's models use (wormsim.contact3d.mjcf)
STATE = ("qpos", "qvel", "act", "qacc_warmstart", "time")
FORWARD = ("qacc", "qfrc_constraint", "efc_force", "sensordata", "actuator_force", "xpos", "cacc")


def _model(integrator: str, collide: bool = True) -> mujoco.MjModel:
    off = "" if collide else 'contype="0" conaffinity="0"'
    return mujoco.MjModel.from_xml_string(XML.format(integrator=integrator, floor=off, box=off))


def _data(m: mujoco.MjModel) -> mujoco.MjData:
    d = mujoco.MjData(m)
    d.qvel[0] = 0.3  # box a slides
    d.qvel[9] = -0.2  # box b turns
    d.ctrl[0] = 0.5
    return d


def _same(d1: mujoco.MjData, d2: mujoco.MjData, names) -> list[str]:
    return [k for k in names if not np.array_equal(np.asarray(getattr(d1, k)), np.asarray(getattr(d2, k)))]


def _contacts(d: mujoco.MjData) -> tuple:
    c = d.contact
    return tuple(np.asarray(getattr(c, k)[: d.ncon]).copy() for k in ("dist", "pos", "frame", "efc_address", "geom"))


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_split_forward_equals_mj_forward(integrator):
    m = _model(integrator)
    d1, d2 = _data(m), _data(m)
    for _ in range(20):  # into contact
        mujoco.mj_step(m, d1)
    for k in STATE:
        setattr(d2, k, np.copy(getattr(d1, k)))
    mujoco.mj_forward(m, d1)
    native.split_forward(m, d2, lambda m, d: None)
    assert d1.ncon >= 4 and d1.nefc >= 12  # the boxes touch: contacts with friction rows
    assert _same(d1, d2, FORWARD) == []
    assert all(np.array_equal(x, y) for x, y in zip(_contacts(d1), _contacts(d2)))


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_split_step_equals_mj_step(integrator):
    m = _model(integrator)
    d1, d2 = _data(m), _data(m)
    for _ in range(200):
        mujoco.mj_step(m, d1)
        native.split_step(m, d2, lambda m, d: None)
    assert d1.ncon >= 4
    assert _same(d1, d2, STATE + FORWARD) == []


@numba.njit
def _step_by_address(fns, m_addr, d_addr, n):
    """native.STEP by address without added contacts (the flank loop's calls, flank_loop.flank_step)."""
    for _ in range(n):
        for s in range(fns.shape[0] - 1):  # the last is mj_addContact
            native.call_stage(fns[s], m_addr, d_addr)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_compiled_stage_list_equals_mj_step(integrator):
    m = _model(integrator)
    d1, d2 = _data(m), _data(m)
    for _ in range(200):
        mujoco.mj_step(m, d1)
    _step_by_address(native.stage_addresses(), m._address, d2._address, 200)
    assert d1.ncon >= 4
    assert _same(d1, d2, STATE + FORWARD) == []


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_added_contacts_enter_the_solver_as_mujocos_own(integrator):
    """The same model with its collision off and, in the ADD_CONTACTS slot, the contacts MuJoCo's collision finds
    at that state (mj_collision on a scratch copy): the same steps as mj_step with the collision on."""
    m_on, m_off = _model(integrator), _model(integrator, collide=False)
    d_on, d_off = _data(m_on), _data(m_off)
    scratch = mujoco.MjData(m_on)

    def add(m, d):
        scratch.qpos[:] = d.qpos
        mujoco.mj_kinematics(m_on, scratch)
        mujoco.mj_collision(m_on, scratch)
        for k in range(scratch.ncon):
            assert mujoco.mj_addContact(m, d, scratch.contact[k]) == 0

    for _ in range(200):
        mujoco.mj_step(m_on, d_on)
        native.split_step(m_off, d_off, add)
    assert d_on.ncon >= 4 and d_on.ncon == d_off.ncon
    assert _same(d_on, d_off, STATE + FORWARD) == []


def test_stage_lists_are_one_table():
    """split_step, split_forward and the compiled loop read one list: STEP is the position stages between the checks
    and the velocity stage, FORWARD the position stages then mj_forwardSkip; the compiled addresses follow STEP."""
    assert native.STEP[2 : 2 + len(native.POSITION)] == native.POSITION
    assert native.FORWARD[: len(native.POSITION)] == native.POSITION
    assert native.STEP[native.N_BEFORE] == native.ADD_CONTACTS
    names = [s for s in native.STEP if s != native.ADD_CONTACTS]
    assert list(native.stage_addresses()) == [native.address(s) for s in names] + [native.MJ_ADD_CONTACT]


def test_mjdata_layout_checks_on_this_mujoco():
    """The offsets the compiled loop reads are MuJoCo's declared layout and read back the bindings' values."""
    off = native.mjdata_offsets()
    assert off.min() >= 0 and native.check(off) == [], off


def test_mjdata_layout_that_does_not_check_raises_with_the_version(monkeypatch):
    """A layout that does not match (here: mjData's time moved by 8 bytes, as a MuJoCo upgrade could) raises naming
    the MuJoCo version and the fields; never a silent fallback."""
    declared = native.declared_offsets()

    def moved():
        off = declared.copy()
        off[0] += 8
        return off

    monkeypatch.setattr(native, "declared_offsets", moved)
    native.mjdata_offsets.cache_clear()
    try:
        with pytest.raises(native.MjDataLayoutError, match=rf"MuJoCo {re.escape(mujoco.__version__)}.*'time'"):
            native.mjdata_offsets()
    finally:
        native.mjdata_offsets.cache_clear()
