"""Where the compiled loop reads mjData: the byte offsets of its scalar fields and arena pointers, from MuJoCo's own
declaration of its structs (mujoco.introspect, the headers' fields in order, shipped with the bindings) laid out by
ctypes with the C rules, and checked once per process by reading values back through them on a small model.

A layout that does not check raises MjDataLayoutError naming the MuJoCo version: the compiled flank loop never runs
on offsets it has not verified, and never falls back silently."""

from __future__ import annotations

import ctypes
import functools

import mujoco
import numpy as np
from mujoco.introspect import ast_nodes, structs

# the C types of the headers' scalar typedefs (mjtnum.h, mjtype.h, stdint.h)
_SCALARS = {
    "mjtNum": ctypes.c_double,
    "int": ctypes.c_int,
    "mjtBool": ctypes.c_ubyte,
    "mjtByte": ctypes.c_ubyte,
    "mjtSize": ctypes.c_int64,
    "size_t": ctypes.c_size_t,
    "uintptr_t": ctypes.c_size_t,
    "uint64_t": ctypes.c_uint64,
    "float": ctypes.c_float,
    "double": ctypes.c_double,
    "char": ctypes.c_char,
}
# the layout vector, in this order (flank_samples.run_samples reads it so)
FIELDS = ("time", "ncon", "nefc", "contact", "efc_force", "badqacc_number", "contact_size", "contact_efc_address")


class MjDataLayoutError(RuntimeError):
    """mjData's layout as declared does not match the library's memory (an unknown MuJoCo version or build)."""


def _ctype(t):
    if isinstance(t, ast_nodes.PointerType):
        return ctypes.c_void_p
    if isinstance(t, ast_nodes.ArrayType):
        c = _ctype(t.inner_type)
        for n in reversed(t.extents):
            c = c * n
        return c
    if t.name in _SCALARS:
        return _SCALARS[t.name]
    if t.name in structs.STRUCTS:
        return _struct(t.name)
    if t.name.startswith("mjt"):  # an enum
        return ctypes.c_int
    raise MjDataLayoutError(f"MuJoCo {mujoco.__version__}: no C type for {t.name!r} in mujoco.introspect")


@functools.cache
def _struct(name: str) -> type[ctypes.Structure]:
    decl = structs.STRUCTS[name]
    fields = []
    for f in decl.fields:
        if not isinstance(f, ast_nodes.StructFieldDecl):
            raise MjDataLayoutError(f"MuJoCo {mujoco.__version__}: {name} has a field that is not plain: {f}")
        fields.append((f.name, _ctype(f.type)))
    return type(name, (ctypes.Structure,), {"_fields_": fields})


def declared_offsets() -> np.ndarray:
    """The offsets of FIELDS from the declared structs (no check)."""
    D, C, W = _struct("mjData"), _struct("mjContact"), _struct("mjWarningStat")
    badqacc = D.warning.offset + ctypes.sizeof(W) * int(mujoco.mjtWarning.mjWARN_BADQACC) + W.number.offset
    return np.array(
        [
            D.time.offset,
            D.ncon.offset,
            D.nefc.offset,
            D.contact.offset,
            D.efc_force.offset,
            badqacc,
            ctypes.sizeof(C),
            C.efc_address.offset,
        ],
        dtype=np.int64,
    )


def check(off: np.ndarray) -> list[str]:
    """The fields whose values read back through off differ from the bindings' (on a box resting on a plane, after a
    step: contacts, constraint rows and a time that are not zero)."""
    m = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><geom type='plane' size='1 1 .1'/><body pos='0 0 .099'><freejoint/>"
        "<geom type='box' size='.1 .1 .1'/></body></worldbody></mujoco>"
    )
    d = mujoco.MjData(m)
    d.time = 0.25
    mujoco.mj_step(m, d)
    d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number = 7
    a = d._address
    o = [int(x) for x in off]
    con = np.asarray(d.contact.dist).ctypes.data  # dist is mjContact's first field
    got = {
        "time": (ctypes.c_double.from_address(a + o[0]).value, d.time),
        "ncon": (ctypes.c_int.from_address(a + o[1]).value, d.ncon),
        "nefc": (ctypes.c_int.from_address(a + o[2]).value, d.nefc),
        "contact": (ctypes.c_int64.from_address(a + o[3]).value, con),
        "efc_force": (ctypes.c_int64.from_address(a + o[4]).value, np.asarray(d.efc_force).ctypes.data),
        "badqacc_number": (ctypes.c_int.from_address(a + o[5]).value, 7),
        "contact_size": (o[6], np.asarray(d.contact.dist).strides[0]),
    }
    if d.ncon >= 1:
        last = ctypes.c_int.from_address(con + o[6] * (d.ncon - 1) + o[7]).value
        got["contact_efc_address"] = (last, int(d.contact.efc_address[d.ncon - 1]))
    else:
        got["contact_efc_address"] = (0, 1)
    d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number = 0
    return [k for k, (x, y) in got.items() if x != y]


@functools.cache
def mjdata_offsets() -> np.ndarray:
    """The checked offsets of FIELDS; MjDataLayoutError where they do not check (module docstring)."""
    try:
        off = declared_offsets()
    except (KeyError, AttributeError) as exc:
        raise MjDataLayoutError(
            f"MuJoCo {mujoco.__version__}: mujoco.introspect does not declare the mjData fields the compiled flank "
            f"loop reads ({exc}); update wormsim.contact3d.mjdata_layout for this version"
        ) from exc
    bad = check(off)
    if bad:
        raise MjDataLayoutError(
            f"MuJoCo {mujoco.__version__}: mjData's fields {bad} are not where mujoco.introspect declares them "
            f"(offsets {dict(zip(FIELDS, off.tolist()))}); the compiled flank loop cannot read this build: update "
            f"wormsim.contact3d.mjdata_layout for this version"
        )
    return off
