"""MuJoCo's native side, as the compiled exact-flank path calls it: the shared library, the call and pointer
intrinsics, MuJoCo's step and forward as one list of stage calls, and where mjData's fields lie.

The library is the one the mujoco package loaded (libmujoco in its folder; dlopen returns the loaded copy); its C
functions are called from compiled code through their addresses (`call_stage`, `call_add`): the address is an
argument, so the callers can be cached, and no ctypes object is unboxed per call.

The stage list (`STEP`, `FORWARD`): mj_step (MuJoCo 4.0.0, engine_forward.c) is mj_checkPos, mj_checkVel, mj_forward,
mj_checkAcc, integrate, and mj_forward's position stage (mj_fwdPosition) is kinematics (mj_fwdKinematics), inertia
(mj_makeM, mj_factorM), mj_collision, mj_makeConstraint, mj_island, mj_transmission, mj_projectConstraint.
`split_step` runs the same stages one by one and adds contacts (`ADD_CONTACTS`: the exact flanks,
wormsim.contact3d.flank_step) between mj_collision (which empties the contact list and its arena) and
mj_makeConstraint (which turns the contacts into constraint rows), then mj_sensorPos, mj_fwdVelocity, mj_sensorVel
and mj_step2 (actuation, acceleration, constraint solve, mj_sensorAcc, mj_checkAcc, and the implicit or Euler
integrator: RK4 is not available this way, MuJoCo's mj_step2 falls back to Euler). `split_forward` runs the position
stages and then mj_forwardSkip from the velocity stage on. Energy is not computed (the template disables it). The
compiled step loop (wormsim.contact3d.flank_loop) calls the same list by address (`stage_addresses`). Each stage
list is tested against MuJoCo's own mj_step / mj_forward (tests/contact3d/test_native.py).

mjData's layout (`mjdata_offsets`): the byte offsets of the scalar fields and arena pointers the compiled samples read
(wormsim.contact3d.flank_samples), from MuJoCo's own declaration of its structs (mujoco.introspect, the headers'
fields in order, shipped with the bindings) laid out by ctypes with the C rules, and checked once per process by
reading values back through them on a small model. A layout that does not check raises MjDataLayoutError naming the
MuJoCo version: the compiled loop never runs on offsets it has not verified, and never falls back silently.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import os

import mujoco
import numba
import numpy as np
from llvmlite import ir
from mujoco.introspect import ast_nodes, structs
from numba import types
from numba.extending import intrinsic

# ---------------------------------------------------------------------------------------------------- the library


@functools.cache
def library() -> ctypes.CDLL:
    """The libmujoco the mujoco package loaded."""
    folder = os.path.dirname(mujoco.__file__)
    paths = sorted(
        glob.glob(os.path.join(folder, "libmujoco.so*")) + glob.glob(os.path.join(folder, "libmujoco*.dylib"))
    )
    if not paths:
        raise ImportError(f"no libmujoco shared library in {folder}")
    return ctypes.CDLL(paths[0])


def address(name: str) -> int:
    """The address of MuJoCo's C function `name`."""
    return int(ctypes.cast(getattr(library(), name), ctypes.c_void_p).value)


MJ_ADD_CONTACT = address("mj_addContact")  # int mj_addContact(const mjModel*, mjData*, const mjContact*)

# ---------------------------------------------------------------------------------------------------- the stages

ADD_CONTACTS = "add_contacts"  # the stage list's slot for the added contacts (after mj_collision)
POSITION = (
    "mj_fwdKinematics",
    "mj_makeM",
    "mj_factorM",
    "mj_collision",
    ADD_CONTACTS,
    "mj_makeConstraint",
    "mj_island",
    "mj_transmission",
    "mj_projectConstraint",
    "mj_sensorPos",
)
STEP = ("mj_checkPos", "mj_checkVel", *POSITION, "mj_fwdVelocity", "mj_sensorVel", "mj_step2")
FORWARD = (*POSITION, "mj_forwardSkip")  # mj_forwardSkip from the velocity stage on (mjSTAGE_POS skipped)
N_BEFORE = STEP.index(ADD_CONTACTS)  # the stages of STEP before the added contacts


def _forward_from_velocity(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    mujoco.mj_forwardSkip(m, d, mujoco.mjtStage.mjSTAGE_POS, 0)


def _calls(names: tuple[str, ...]) -> tuple:
    return tuple(
        None if s == ADD_CONTACTS else _forward_from_velocity if s == "mj_forwardSkip" else getattr(mujoco, s)
        for s in names
    )


_STEP_CALLS, _FORWARD_CALLS = _calls(STEP), _calls(FORWARD)


def _run(calls: tuple, m: mujoco.MjModel, d: mujoco.MjData, add_contacts) -> None:
    for f in calls:
        if f is None:
            add_contacts(m, d)
        else:
            f(m, d)


def split_step(m: mujoco.MjModel, d: mujoco.MjData, add_contacts) -> None:
    """mj_step with add_contacts(m, d) called between mj_collision and mj_makeConstraint (STEP)."""
    _run(_STEP_CALLS, m, d, add_contacts)


def split_forward(m: mujoco.MjModel, d: mujoco.MjData, add_contacts) -> None:
    """mj_forward with the added contacts (FORWARD: for the initial state and for checks)."""
    _run(_FORWARD_CALLS, m, d, add_contacts)


def stage_addresses() -> np.ndarray:
    """STEP's C functions by address for the compiled loop: the stages without ADD_CONTACTS in order, then
    mj_addContact (all stages are `void f(const mjModel*, mjData*)`)."""
    names = [s for s in STEP if s != ADD_CONTACTS]
    return np.array([address(s) for s in names] + [MJ_ADD_CONTACT], dtype=np.int64)


# ---------------------------------------------------------------------------------------------------- intrinsics


def _void_call(n):
    """codegen of void fn(n pointers) called through its address (the first argument; all int64)."""

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.VoidType(), [ir.IntType(8).as_pointer()] * n)
        f = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(f, [builder.inttoptr(a, ir.IntType(8).as_pointer()) for a in args[1:]])
        return context.get_dummy_value()

    return codegen


@intrinsic
def call_stage(typingctx, fn, m_addr, d_addr):
    """void fn(const mjModel*, mjData*) called through its address (all int64)."""
    return types.void(types.int64, types.int64, types.int64), _void_call(2)


@intrinsic
def call_add(typingctx, fn, m_addr, d_addr, c_addr):
    """int fn(const mjModel*, mjData*, const mjContact*) called through its address (all four int64)."""
    sig = types.int32(types.int64, types.int64, types.int64, types.int64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(8).as_pointer()] * 3)
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [builder.inttoptr(a, ir.IntType(8).as_pointer()) for a in args[1:]])

    return sig, codegen


@intrinsic
def call_mul(typingctx, fn, m_addr, d_addr, res_addr, vec_addr):
    """void fn(const mjModel*, const mjData*, mjtNum* res, const mjtNum* vec) called through its address (all
    int64): mj_mulJacVec."""
    return types.void(types.int64, types.int64, types.int64, types.int64, types.int64), _void_call(4)


def _pointer_at(nbtype):
    """An intrinsic: the `nbtype` pointer at an address (int64)."""

    def impl(typingctx, addr):
        sig = types.CPointer(nbtype)(types.int64)

        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], context.get_value_type(types.CPointer(nbtype)))

        return sig, codegen

    impl.__name__ = f"{nbtype}_at"
    return intrinsic(impl)


f64_at = _pointer_at(types.float64)
f32_at = _pointer_at(types.float32)
i64_at = _pointer_at(types.int64)
i32_at = _pointer_at(types.int32)


# arrays by (address, shape) rows of an int64 table T (wormsim.contact3d.flank_loop's address tables)
@numba.njit(cache=True, inline="always")
def f1(T, k):
    return numba.carray(f64_at(T[k, 0]), (T[k, 1],))


@numba.njit(cache=True, inline="always")
def f2(T, k):
    return numba.carray(f64_at(T[k, 0]), (T[k, 1], T[k, 2]))


@numba.njit(cache=True, inline="always")
def f3(T, k):
    return numba.carray(f64_at(T[k, 0]), (T[k, 1], T[k, 2], T[k, 3]))


@numba.njit(cache=True, inline="always")
def f32x3(T, k):
    return numba.carray(f32_at(T[k, 0]), (T[k, 1], T[k, 2], T[k, 3]))


@numba.njit(cache=True, inline="always")
def i1(T, k):
    return numba.carray(i64_at(T[k, 0]), (T[k, 1],))


# ---------------------------------------------------------------------------------------------------- mjData layout

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
# badq_number: the count of mjWARN_BADQPOS, whose mjWarningStat is followed by BADQVEL's and BADQACC's (warning_size
# apart): MuJoCo resets the state and the time on each (mj_checkPos / mj_checkVel / mj_checkAcc)
FIELDS = ("time", "ncon", "nefc", "contact", "efc_force", "badq_number", "contact_size", "contact_efc_address")
FIELDS += ("warning_size", "contact_dim", "contact_friction", "efc_vel")
BAD_STATE_WARNINGS = ("mjWARN_BADQPOS", "mjWARN_BADQVEL", "mjWARN_BADQACC")


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
    bad = [int(getattr(mujoco.mjtWarning, w)) for w in BAD_STATE_WARNINGS]
    if bad != list(range(bad[0], bad[0] + len(bad))):
        raise KeyError(f"{BAD_STATE_WARNINGS} are not consecutive in mjtWarning ({bad})")
    badq = D.warning.offset + ctypes.sizeof(W) * bad[0] + W.number.offset
    return np.array(
        [
            D.time.offset,
            D.ncon.offset,
            D.nefc.offset,
            D.contact.offset,
            D.efc_force.offset,
            badq,
            ctypes.sizeof(C),
            C.efc_address.offset,
            ctypes.sizeof(W),
            C.dim.offset,
            C.friction.offset,
            D.efc_vel.offset,
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
    for k, w in enumerate(BAD_STATE_WARNINGS):
        d.warning[getattr(mujoco.mjtWarning, w)].number = 7 + k
    a = d._address
    o = [int(x) for x in off]
    con = np.asarray(d.contact.dist).ctypes.data  # dist is mjContact's first field
    got = {
        "time": (ctypes.c_double.from_address(a + o[0]).value, d.time),
        "ncon": (ctypes.c_int.from_address(a + o[1]).value, d.ncon),
        "nefc": (ctypes.c_int.from_address(a + o[2]).value, d.nefc),
        "contact": (ctypes.c_int64.from_address(a + o[3]).value, con),
        "efc_force": (ctypes.c_int64.from_address(a + o[4]).value, np.asarray(d.efc_force).ctypes.data),
        "badq_number": (
            [ctypes.c_int.from_address(a + o[5] + k * o[8]).value for k in range(len(BAD_STATE_WARNINGS))],
            [7 + k for k in range(len(BAD_STATE_WARNINGS))],
        ),
        "contact_size": (o[6], np.asarray(d.contact.dist).strides[0]),
        "efc_vel": (ctypes.c_int64.from_address(a + o[11]).value, np.asarray(d.efc_vel).ctypes.data),
    }
    if d.ncon >= 1:
        k = d.ncon - 1
        last = con + o[6] * k
        got["contact_efc_address"] = (ctypes.c_int.from_address(last + o[7]).value, int(d.contact.efc_address[k]))
        got["contact_dim"] = (ctypes.c_int.from_address(last + o[9]).value, int(d.contact.dim[k]))
        d.contact.friction[k, 0] = 0.375  # a value of its own (the box's friction is the default's)
        got["contact_friction"] = (ctypes.c_double.from_address(last + o[10]).value, 0.375)
    else:
        got["contact_efc_address"] = got["contact_dim"] = got["contact_friction"] = (0, 1)
    for w in BAD_STATE_WARNINGS:
        d.warning[getattr(mujoco.mjtWarning, w)].number = 0
    return [k for k, (x, y) in got.items() if x != y]


@functools.cache
def mjdata_offsets() -> np.ndarray:
    """The checked offsets of FIELDS; MjDataLayoutError where they do not check (module docstring)."""
    try:
        off = declared_offsets()
    except (KeyError, AttributeError) as exc:
        raise MjDataLayoutError(
            f"MuJoCo {mujoco.__version__}: mujoco.introspect does not declare the mjData fields the compiled flank "
            f"loop reads ({exc}); update wormsim.contact3d.native for this version"
        ) from exc
    bad = check(off)
    if bad:
        raise MjDataLayoutError(
            f"MuJoCo {mujoco.__version__}: mjData's fields {bad} are not where mujoco.introspect declares them "
            f"(offsets {dict(zip(FIELDS, off.tolist()))}); the compiled flank loop cannot read this build: update "
            f"wormsim.contact3d.native for this version"
        )
    return off
