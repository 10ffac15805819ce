"""The mesh's contact sensor (wormsim.contact3d.mjcf: worm against the wheel's subtree, reduce="netforce") computed
in the compiled flank loop, so that MuJoCo's mj_sensorAcc runs only on the step whose sensordata is kept (the last
of a record interval; wormsim.contact3d.flank_loop.run_table turns MuJoCo's sensors off on the others with
mjDSBL_SENSOR: the sensors are outputs only, nothing in the dynamics reads them).

`net_contact` is MuJoCo's own computation (MuJoCo 4.0.0, engine_sensor.c, mj_computeSensorAcc, case mjSENS_CONTACT
with the netforce reduction, and its helpers matchContact, mj_contactForce, total_wrench) with the same
floating-point operations in the same order, so the values are bit-identical to sensordata
(tests/contact3d/test_net_contact.py, step by step on a flank run): the contacts whose geoms match the sensor's
objects (object 1 a body: the geom's body; object 2 an xbody: the geom's body or one below it; the direction flips
where the contact's geoms come the other way round), each one's wrench (efc_force's rows of its contact, dim of them;
negated where flipped), the point (the contacts' positions weighted by |force| over their sum), the total force and
its moment about the point in the global frame. Written as sensordata lays it out for mjcf.MESH_SENSOR_DATA: found,
force (3), torque (3), point (3).

Cost: mj_sensorAcc ~3.3 us per step on the seat motor's ~92 contacts (studies/profile_flank_step.py), this ~1 us.
"""

from __future__ import annotations

import ctypes
import math

import mujoco
import numba
import numpy as np

from wormsim.contact3d.native import _struct, f64_at, i32_at

SIZE = 10  # found, force (3), torque (3), point (3)
DATA = 1 | 2 | 4 | 16  # mjtConDataField bits of these fields (wormsim.contact3d.mjcf.MESH_SENSOR_DATA)
NETFORCE = 3  # the sensor's reduce
BODIES = (int(mujoco.mjtObj.mjOBJ_BODY), int(mujoco.mjtObj.mjOBJ_XBODY))
MINVAL = 1e-15  # mjMINVAL
OBJ1, OBJ2 = 1, 2  # gmatch's bits: the geom matches the sensor's object 1, object 2
# mjContact's fields by byte offset, in the order `net_contact` takes them (native._struct: the declared layout)
CONTACT_FIELDS = ("geom", "pos", "frame", "dim", "efc_address")


def contact_offsets() -> np.ndarray:
    """(the CONTACT_FIELDS' byte offsets in mjContact, its size)."""
    C = _struct("mjContact")
    return np.array([getattr(C, f).offset for f in CONTACT_FIELDS] + [ctypes.sizeof(C)], dtype=np.int64)


def sensor_id(m: mujoco.MjModel, adr: int) -> int:
    """The contact sensor whose values start at sensordata[adr], where net_contact computes it (a contact sensor,
    netforce reduction, the fields DATA, one slot, bodies on both sides); else -1."""
    for i in range(m.nsensor):
        if (
            int(m.sensor_adr[i]) == adr
            and int(m.sensor_type[i]) == int(mujoco.mjtSensor.mjSENS_CONTACT)
            and int(m.sensor_intprm[i, 0]) == DATA
            and int(m.sensor_intprm[i, 1]) == NETFORCE
            and int(m.sensor_dim[i]) == SIZE
            and int(m.sensor_objtype[i]) in BODIES
            and int(m.sensor_reftype[i]) in BODIES
            and m.sensor_noise[i] == 0.0
            and m.sensor_cutoff[i] == 0.0
        ):
            return i
    return -1


def geom_match(m: mujoco.MjModel, sensor: int) -> np.ndarray:
    """Per geom the bits OBJ1 (its body is the contact sensor's object 1) and OBJ2 (its body is object 2 or, an xbody,
    below it): matchContact's checkMatch per geom, for a sensor with a body (or xbody) on both sides."""
    out = np.zeros(m.ngeom, dtype=np.int64)
    xbody = int(mujoco.mjtObj.mjOBJ_XBODY)
    for bit, typ, oid in (
        (OBJ1, int(m.sensor_objtype[sensor]), int(m.sensor_objid[sensor])),
        (OBJ2, int(m.sensor_reftype[sensor]), int(m.sensor_refid[sensor])),
    ):
        if typ not in BODIES:
            raise ValueError(f"net_contact: the contact sensor's objects must be bodies, not {typ}")
        for g in range(m.ngeom):
            b = int(m.geom_bodyid[g])
            if typ == xbody:
                while b > oid:
                    b = int(m.body_parentid[b])
            if b == oid:
                out[g] |= bit
    return out


@numba.njit(cache=True, inline="always")
def _match(gmatch, rec, og):
    """matchContact with both sensor objects given: 0 no match, 1 the contact's direction, -1 flipped."""
    gp = i32_at(rec + og)
    g1, g2 = gp[0], gp[1]
    b1 = gmatch[g1] if g1 >= 0 else 0
    b2 = gmatch[g2] if g2 >= 0 else 0
    m11, m12, m21, m22 = b1 & OBJ1, b2 & OBJ1, b1 & OBJ2, b2 & OBJ2
    if m11 == 0 and m12 == 0:
        return 0
    if m21 == 0 and m22 == 0:
        return 0
    regular = m11 != 0 and m22 != 0
    reverse = m12 != 0 and m21 != 0
    if regular:
        return 1
    if reverse:
        return -1
    return 0


@numba.njit(cache=True, inline="always")
def _wrench(rec, co, efc, flip, w):
    """mj_contactForce (elliptic cones: efc_force's dim rows of the contact; zeros without rows) into w (6,), negated
    where flip (mju_scl by -1)."""
    for k in range(6):
        w[k] = 0.0
    adr = i32_at(rec + co[4])[0]
    if adr >= 0:
        dim = i32_at(rec + co[3])[0]
        for k in range(dim):
            w[k] = efc[adr + k]
    if flip:
        for k in range(6):
            w[k] = w[k] * -1.0
    return w


@numba.njit(cache=True)
def net_contact(base, ncon, co, efc, gmatch, out, w):
    """The sensor's values (module docstring) into out (SIZE,): the contacts d.contact[0..ncon-1] at address base,
    co = contact_offsets(), efc d.efc_force, gmatch = geom_match(...), w a (6,) work array."""
    og, op, of = co[0], co[1], co[2]
    size = co[5]
    nmatch = 0
    p0 = p1 = p2 = 0.0
    total = 0.0
    for j in range(ncon):
        rec = base + j * size
        mt = _match(gmatch, rec, og)
        if mt == 0:
            continue
        nmatch += 1
        _wrench(rec, co, efc, mt < 0, w)
        weight = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])  # mju_norm3
        pos = f64_at(rec + op)
        p0 += pos[0] * weight
        p1 += pos[1] * weight
        p2 += pos[2] * weight
        total += weight
    s = 1.0 / max(total, MINVAL)
    p0, p1, p2 = p0 * s, p1 * s, p2 * s
    f0 = f1 = f2 = 0.0
    t0 = t1 = t2 = 0.0
    for j in range(ncon):  # total_wrench over the same contacts in the same order
        rec = base + j * size
        mt = _match(gmatch, rec, og)
        if mt == 0:
            continue
        _wrench(rec, co, efc, mt < 0, w)
        fr = f64_at(rec + of)
        pos = f64_at(rec + op)
        # mju_mulMatTVec3: the frame's rows are the contact's axes
        fj0 = fr[0] * w[0] + fr[3] * w[1] + fr[6] * w[2]
        fj1 = fr[1] * w[0] + fr[4] * w[1] + fr[7] * w[2]
        fj2 = fr[2] * w[0] + fr[5] * w[1] + fr[8] * w[2]
        tj0 = fr[0] * w[3] + fr[3] * w[4] + fr[6] * w[5]
        tj1 = fr[1] * w[3] + fr[4] * w[4] + fr[7] * w[5]
        tj2 = fr[2] * w[3] + fr[5] * w[4] + fr[8] * w[5]
        f0, f1, f2 = f0 + fj0, f1 + fj1, f2 + fj2
        t0, t1, t2 = t0 + tj0, t1 + tj1, t2 + tj2
        d0, d1, d2 = pos[0] - p0, pos[1] - p1, pos[2] - p2
        t0 = t0 + (d1 * fj2 - d2 * fj1)  # mju_cross(diff, force_j)
        t1 = t1 + (d2 * fj0 - d0 * fj2)
        t2 = t2 + (d0 * fj1 - d1 * fj0)
    out[0] = nmatch
    out[1], out[2], out[3] = f0, f1, f2
    out[4], out[5], out[6] = t0, t1, t2
    out[7], out[8], out[9] = p0, p1, p2
