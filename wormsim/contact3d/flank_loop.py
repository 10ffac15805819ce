"""The exact-flank step loop compiled: the steps of one record interval of wormsim.contact3d.runner in one
numba call, MuJoCo's C stage functions called by address.

Each step does what the runner's Python loop did with `FlankContacts.step` (wormsim.contact3d.flank_step), in the
same order and with the same floating-point operations, so the results are bit-identical
(tests/test_flank_loop.py): the drive and load commands into d.ctrl, the shaft speeds read, then `split_step`'s stages
(mj_checkPos, mj_checkVel, mj_fwdKinematics, mj_makeM, mj_factorM, mj_collision; the flank contacts: the window
update of FlankContacts.window, with assembly errors flank_pose.set_pose, kernel.find_packed (find_contacts with
its memo, slice_weights, contact_frames), flank_handoff._fill_add; mj_makeConstraint, mj_island, mj_transmission,
mj_projectConstraint, mj_sensorPos, mj_fwdVelocity, mj_sensorVel, mj_step2), then the runner's per-step sums
(actuator torques, shaft powers T w, the contact sensor's count, force and moment, the peak |F_x|).

The stages are the functions of the shared library the mujoco package loaded (flank_handoff._library), called through
their addresses as flank_handoff calls mj_addContact; all are `void f(const mjModel*, mjData*)`. What this skips of
the Python binding is its error interception: an mju_error inside a stage (MuJoCo's fatal errors, e.g. its arena
exhausted) is not turned into a Python exception here. MuJoCo's warnings (d.warning) are counted as before, and the
runner's guards read them after each interval.

`sample` is the runner's per-sample work on the flank contacts in one compiled call (`sample_flanks`, which
flank_samples.run_samples calls too): flank_step._contact_forces (forces, points, teeth touching; with displaced
poses the points via the displaced wheel body's frame), the largest penetration, hertz._rows (the contact pattern's
rows), contact_sums.radial_and_radius, and the points stored into the run's arrays.

Both take their per-run arrays as one table of addresses and shapes (`run_table`, `sample_table`: numba's unboxing of
~30 arrays cost 10-20 us per call). Flank runs turn MuJoCo's islands off (`FlankLoop`: two dofs, one island; measured
bit-identical). Cost and checks: docs/contact3d.md, "Exact flanks: the step loop compiled" (the Python loop spent
about 1.3-3.5 us per stage call on the binding and 10-20 us per step on the runner's per-step reads and sums).
"""

from __future__ import annotations

import ctypes
import enum
import math

import mujoco
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from wormsim.contact3d.contact_sums import radial_and_radius, radius_mean
from wormsim.contact3d.flank_handoff import _MJ_ADD_CONTACT, _f64_at, _fill_add, _library
from wormsim.contact3d.flank_step import _contact_forces
from wormsim.contact3d.series import N_SUMS, add_step
from wormsim.tooth.hertz import _rows
from wormsim.tooth.kernel import find_packed
from wormsim.tooth.pose import set_pose

STAGES_BEFORE = ("mj_checkPos", "mj_checkVel", "mj_fwdKinematics", "mj_makeM", "mj_factorM", "mj_collision")
STAGES_AFTER = (
    "mj_makeConstraint",
    "mj_island",
    "mj_transmission",
    "mj_projectConstraint",
    "mj_sensorPos",
    "mj_fwdVelocity",
    "mj_sensorVel",
    "mj_step2",
)
N_BEFORE = len(STAGES_BEFORE)  # the stages before the flank contacts are added
NO_WINDOW = np.iinfo(np.int64).min  # the window's first centre is not set yet
# run_interval's integer and float parameters (FlankLoop.iv, FlankLoop.fv): the rows by name, the one declaration
IV = enum.IntEnum(
    "IV",
    (
        "drive_actuator",
        "load_actuator",
        "worm_dof",
        "wheel_dof",
        "worm_actuator",  # the worm shaft's actuator (the drive's or the load's)
        "wheel_actuator",
        "sensor",  # the contact sensor's address in sensordata
        "worm_qpos",
        "wheel_qpos",
        "worm_body",
        "wheel_body",
        "displaced",  # assembly errors: the poses from the bodies (wormsim.tooth.pose)
        "window_teeth",
        "slices",
        "record_size",  # the mjContact record's size
        "record_base",  # the record buffer's address
        "friction_rows",  # solreffriction written into the records
    ),
    start=0,
)
FV = enum.IntEnum("FV", ("tooth0", "pitch", "margin", "taper", "mu"), start=0)


def _addresses() -> np.ndarray:
    lib = _library()
    names = STAGES_BEFORE + STAGES_AFTER
    return np.array([ctypes.cast(getattr(lib, s), ctypes.c_void_p).value for s in names], dtype=np.int64)


STAGE_ADDRESSES = _addresses()


@intrinsic
def _call_stage(typingctx, fn, m_addr, d_addr):
    """void fn(const mjModel*, mjData*) called through its address (all int64; as flank_handoff._call_add)."""
    sig = types.void(types.int64, types.int64, types.int64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.VoidType(), [ir.IntType(8).as_pointer()] * 2)
        f = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(f, [builder.inttoptr(a, ir.IntType(8).as_pointer()) for a in args[1:]])
        return context.get_dummy_value()

    return sig, codegen


@numba.njit(cache=True)
def run_interval(fns, m_addr, d_addr, cmd, load, j0, j1, mjd, iv, fv, state, kern, params, out, hand, acc):
    """Steps j0..j1-1 of the command arrays cmd (drive) and load (module docstring).

    mjd = (ctrl, qvel, qpos, actuator_force, sensordata, xpos, xmat): d's own arrays;
    iv, fv: the integer and float parameters (rows IV, FV: the actuators, dofs, qpos addresses, bodies, window and
    records; tooth 0's angle, the pitch angle, margin, taper, friction coefficient);
    state = (the window's centre tooth, the last step's contact count);
    kern = FlankContacts.kernel's buffers (fb, ib; flanks.PackedKernel) and ks (the window's teeth, a view of ib);
    params = the kernel's P (a view of fb);
    out = the kernel's (pos, depth, weight, frame, mfric), the merged ones with one contact per tooth flank
    (FlankContacts.handed, wormsim.tooth.merge);
    hand = (records, field offsets, solref, solreffriction).
    acc (series.SUMS) receives the sums over the steps (series.add_step). Returns the number of contacts MuJoCo did
    not take (arena full) summed over the steps."""
    ctrl, qvel, qpos, act, sd, xpos, xmat = mjd
    ia_drv, ia_load, dof1, dof2 = iv[IV.drive_actuator], iv[IV.load_actuator], iv[IV.worm_dof], iv[IV.wheel_dof]
    a1, a2, s0 = iv[IV.worm_actuator], iv[IV.wheel_actuator], iv[IV.sensor]
    qa1, qa2 = iv[IV.worm_qpos], iv[IV.wheel_qpos]
    worm_body, wheel_body, displaced, W = iv[IV.worm_body], iv[IV.wheel_body], iv[IV.displaced], iv[IV.window_teeth]
    size, base, fr = iv[IV.record_size], iv[IV.record_base], iv[IV.friction_rows]
    tooth0, pitch, margin0, taper, mu = fv[FV.tooth0], fv[FV.pitch], fv[FV.margin], fv[FV.taper], fv[FV.mu]
    fb, ib, ks = kern
    pos, depth, weight, frame, fscale = out
    rec, off, solref, solreffriction = hand
    nb = N_BEFORE
    sums = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    dropped = 0
    for j in range(j0, j1):
        ctrl[ia_drv] = cmd[j]
        ctrl[ia_load] = load[j]
        w1j, w2j = qvel[dof1], qvel[dof2]
        for s in range(nb):
            _call_stage(fns[s], m_addr, d_addr)
        # FlankContacts.add: find, weights, frames, bulk hand-off
        th1, th2 = qpos[qa1], qpos[qa2]
        if displaced:
            set_pose(params, xpos, xmat, worm_body, wheel_body, th1)
        cw = math.floor((-math.pi / 2 - tooth0 - th2) / pitch)
        if cw != state[0]:
            h = W // 2
            for i in range(W):
                ks[i] = cw - h + 1 + i
            state[0] = cw
        n = find_packed(fb, ib, th1, th2, margin0, taper)
        state[1] = n
        nh = ib[7] if ib[6] != 0 else n  # one contact per tooth flank (wormsim.tooth.merge): out holds the merged ones
        if nh:
            k = min(nh, rec.shape[0])
            added = _fill_add(
                fns[fns.shape[0] - 1],
                m_addr,
                d_addr,
                rec,
                base,
                size,
                off,
                k,
                depth,
                pos,
                frame,
                weight,
                solref,
                solreffriction,
                fr != 0,
                fscale,
                mu,
                ib[6] != 0,
            )
            dropped += k - added
        for s in range(nb, fns.shape[0] - 1):
            _call_stage(fns[s], m_addr, d_addr)
        sums = add_step(sums, act, sd, a1, a2, s0, w1j, w2j)  # the per-step sums (wormsim.contact3d.series)
    for k in range(N_SUMS):
        acc[k] = sums[k]
    return dropped


@intrinsic
def _f32_at(typingctx, addr):
    """The float32 pointer at an address (int64)."""
    sig = types.CPointer(types.float32)(types.int64)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(types.CPointer(types.float32)))

    return sig, codegen


@intrinsic
def _i64_at(typingctx, addr):
    """The int64 pointer at an address (int64)."""
    sig = types.CPointer(types.int64)(types.int64)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(types.CPointer(types.int64)))

    return sig, codegen


# the arrays of run_interval in FlankLoop's address table: (name, dtype, ndim) per row, in row order; the one
# declaration of the table's layout (Row: the rows by name, for run_table's unpacking and FlankLoop's arrays)
TABLE = (
    ("ctrl", "f8", 1),  # d.ctrl
    ("qvel", "f8", 1),  # d.qvel
    ("qpos", "f8", 1),  # d.qpos
    ("act", "f8", 1),  # d.actuator_force
    ("sensordata", "f8", 1),  # d.sensordata
    ("xpos", "f8", 2),  # d.xpos
    ("xmat", "f8", 2),  # d.xmat
    ("fb", "f8", 1),  # the kernel's float buffer (flanks.PackedKernel.fb)
    ("ib", "i8", 1),  # its int buffer (ib)
    ("ks", "i8", 1),  # ks (a view of ib)
    ("params", "f8", 1),  # params (P, a view of fb)
    ("pos", "f8", 2),
    ("depth", "f8", 1),
    ("weight", "f8", 1),
    ("frame", "f8", 2),
    ("records", "i8", 2),  # the hand-off's records (as int64 rows; run_interval views them as float64)
    ("rec_off", "i8", 1),  # the records' field offsets
    ("solref", "f8", 1),
    ("solreffriction", "f8", 1),
    ("state", "i8", 1),
    ("acc", "f8", 1),
    ("stages", "i8", 1),  # the stage addresses
    ("iv", "i8", 1),
    ("fv", "f8", 1),
    ("mfric", "f8", 1),  # the merged contacts' friction scale (wormsim.tooth.merge: mfric)
)
Row = enum.IntEnum("Row", [name for name, _, _ in TABLE], start=0)  # T[Row.qpos]: numba reads members as constants


@numba.njit(cache=True, inline="always")
def _f1(T, k):
    return numba.carray(_f64_at(T[k, 0]), (T[k, 1],))


@numba.njit(cache=True, inline="always")
def _f2(T, k):
    return numba.carray(_f64_at(T[k, 0]), (T[k, 1], T[k, 2]))


@numba.njit(cache=True, inline="always")
def _f3(T, k):
    return numba.carray(_f64_at(T[k, 0]), (T[k, 1], T[k, 2], T[k, 3]))


@numba.njit(cache=True, inline="always")
def _f4(T, k):
    return numba.carray(_f64_at(T[k, 0]), (T[k, 1], T[k, 2], T[k, 3], T[k, 4]))


@numba.njit(cache=True, inline="always")
def _f32x3(T, k):
    return numba.carray(_f32_at(T[k, 0]), (T[k, 1], T[k, 2], T[k, 3]))


@numba.njit(cache=True, inline="always")
def _i1(T, k):
    return numba.carray(_i64_at(T[k, 0]), (T[k, 1],))


@numba.njit(cache=True, inline="always")
def _i3(T, k):
    return numba.carray(_i64_at(T[k, 0]), (T[k, 1], T[k, 2], T[k, 3]))


@numba.njit(cache=True, nogil=True)
def run_table(T, m_addr, d_addr, cmd, load, j0, j1):
    """run_interval with its arrays given by address and shape (T: one row per TABLE entry, (address, shape));
    numba unboxes one array instead of 30 per call (about 10-20 us per call saved, docs/contact3d.md). Releases the
    GIL, as MuJoCo's bindings do around mj_step: wormsim.run imports the report's libraries meanwhile."""
    R = Row
    mjd = (_f1(T, R.ctrl), _f1(T, R.qvel), _f1(T, R.qpos), _f1(T, R.act), _f1(T, R.sensordata))
    mjd2 = (_f2(T, R.xpos), _f2(T, R.xmat))
    kern = (_f1(T, R.fb), _i1(T, R.ib), _i1(T, R.ks))
    out = (_f2(T, R.pos), _f1(T, R.depth), _f1(T, R.weight), _f2(T, R.frame), _f1(T, R.mfric))
    rec = _records(T)
    hand = (rec, _i1(T, R.rec_off), _f1(T, R.solref), _f1(T, R.solreffriction))
    iv, fv = _i1(T, R.iv), _f1(T, R.fv)
    state, acc = _i1(T, R.state), _f1(T, R.acc)
    return run_interval(
        _i1(T, R.stages),
        m_addr,
        d_addr,
        cmd,
        load,
        j0,
        j1,
        mjd + mjd2,
        iv,
        fv,
        state,
        kern,
        _f1(T, R.params),
        out,
        hand,
        acc,
    )


@numba.njit(cache=True, inline="always")
def _records(T):
    """The hand-off's records: int64 rows of the same bytes, viewed as float64."""
    return numba.carray(_f64_at(T[Row.records, 0]), (T[Row.records, 1], T[Row.records, 2]))


def address_table(arrays, table=TABLE) -> np.ndarray:
    """T for run_table (sample_table with SAMPLE_TABLE): each array checked against the table (dtype, dimensions, C
    order) and kept by the caller."""
    if len(arrays) != len(table):
        raise RuntimeError("flank_loop: the address table and its layout disagree")
    T = np.zeros((len(arrays), 5), dtype=np.int64)
    for k, (a, (_, dt, nd)) in enumerate(zip(arrays, table)):
        if a.dtype != np.dtype(dt) or a.ndim != nd or not a.flags.c_contiguous:
            raise RuntimeError(
                f"flank_loop: array {k} is {a.dtype} {a.shape}, expected {dt} with {nd} dimensions, C order"
            )
        T[k, 0] = a.ctypes.data
        T[k, 1 : 1 + nd] = a.shape
    return T


@numba.njit(cache=True)
def sample_flanks(
    adr, frame, pos, own, efc_force, ncon, n_fc, cone3, meta, weight, depth, P, th2, z2, a, i, store, work, pat, rlog
):
    """FlankLoop.sample's compiled part (module docstring): adr the contacts' efc_address; frame, pos theirs or,
    where own, the kernel's (the same values: flank_handoff copies them into the contacts); P the kernel's P (the
    poses, with assembly errors: flank_step._contact_forces); store = (points in tooth
    0's frame, forces, points; the run's float32 arrays, row i); work (3, cap, 3); pat = PatternLog's (inv_rho,
    line_len, E*, buffer, rows used); rlog = contact_sums.RadiusLog's (buffer, rows used). Returns (teeth touching,
    largest penetration, F_r,lc, sum w, sum w r, the pattern's rows used, the radius log's rows used)."""
    pts, forces, pts_world = store
    inv_rho, line_len, e_star, buf, pm = pat
    rbuf, rm = rlog
    n = min(n_fc, ncon)
    if n == 0:
        return 0, 0.0, -0.0, 0.0, 0.0, pm, rm
    k0 = ncon - n
    f0 = 0 if own else k0
    m, nteeth = _contact_forces(adr[k0:], frame[f0:], pos[f0:], efc_force, cone3, meta, th2, z2, work, P)
    pen = depth[0]
    for c in range(1, n):
        if depth[c] > pen:
            pen = depth[c]
    pm = _rows(i, adr[k0:ncon], efc_force, meta, weight, inv_rho, line_len, e_star, buf, pm)
    fr, W, wr = radial_and_radius(work[1], work[2], m, a, i, rbuf, rm)
    for c in range(min(m, pts.shape[1])):
        for x in range(3):
            pts[i, c, x] = work[0, c, x]
            forces[i, c, x] = work[1, c, x]
            pts_world[i, c, x] = work[2, c, x]
    return nteeth, pen, fr, W, wr, pm, rm + m


# the per-run arrays of sample_flanks in FlankLoop's sample table: (name, dtype, ndim) per row, in row order
SAMPLE_TABLE = (
    ("meta", "f8", 2),  # meta
    ("weight", "f8", 1),
    ("depth", "f8", 1),
    ("params", "f8", 1),  # the kernel's P (FlankContacts.params)
    ("work", "f8", 3),  # work
    ("inv_rho", "f8", 3),  # PatternLog's inv_rho
    ("line_len", "f8", 3),  # PatternLog's line_len
    ("pts", "f4", 3),  # points in tooth 0's frame (the run's)
    ("forces", "f4", 3),  # forces
    ("pts_world", "f4", 3),  # points
)
SampleRow = enum.IntEnum("SampleRow", [name for name, _, _ in SAMPLE_TABLE], start=0)


@numba.njit(cache=True)
def sample_table(T, adr, frame, pos, own, efc_force, buf, rbuf, ncon, n_fc, cone3, th2, z2, a, i, e_star, pm, rm):
    """sample_flanks with its per-run arrays given by address and shape (T: one row per SAMPLE_TABLE entry)."""
    f32 = (_f32x3(T, SampleRow.pts), _f32x3(T, SampleRow.forces), _f32x3(T, SampleRow.pts_world))
    return sample_flanks(
        adr,
        frame,
        pos,
        own,
        efc_force,
        ncon,
        n_fc,
        cone3,
        _f2(T, SampleRow.meta),
        _f1(T, SampleRow.weight),
        _f1(T, SampleRow.depth),
        _f1(T, SampleRow.params),
        th2,
        z2,
        a,
        i,
        f32,
        _f3(T, SampleRow.work),
        (_f3(T, SampleRow.inv_rho), _f3(T, SampleRow.line_len), e_star, buf, pm),
        (rbuf, rm),
    )


class FlankLoop:
    """run_interval's arguments for one FlankContacts and its MjData (module docstring); `run` steps an interval."""

    def __init__(self, fc, d, drive_actuator: int, load_actuator: int, a1: int, a2: int, sensor_adr: int):
        bm, m = fc.bm, fc.bm.model
        self.fc, self.m, self.d = fc, m, d
        # one island: the worm and the wheel are the model's only dofs and the flank contacts couple them, so
        # MuJoCo's island decomposition (mj_island, ~3.5 us per step) only repartitions the same solve (measured
        # bit-identical: docs/contact3d.md, "Exact flanks: the step loop compiled")
        if m.nv == 2:
            m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ISLAND)
        buf = fc.buffer
        iv = {
            IV.drive_actuator: drive_actuator,
            IV.load_actuator: load_actuator,
            IV.worm_dof: bm.worm_dof,
            IV.wheel_dof: bm.wheel_dof,
            IV.worm_actuator: a1,
            IV.wheel_actuator: a2,
            IV.sensor: sensor_adr,
            IV.worm_qpos: fc.qa1,
            IV.wheel_qpos: fc.qa2,
            IV.worm_body: bm.worm_body,
            IV.wheel_body: bm.wheel_body,
            IV.displaced: int(fc.displaced),
            IV.window_teeth: bm.window_teeth,
            IV.slices: fc.slices,
            IV.record_size: buf.size,
            IV.record_base: buf.address,
            IV.friction_rows: 0,  # `prepare`
        }
        self.iv = np.array([iv[k] for k in IV], dtype=np.int64)
        fv = {FV.tooth0: float(bm.tooth0_angle_rad), FV.pitch: fc.pitch, FV.margin: fc.margin0, FV.taper: fc.taper_rad}
        self.fv = np.array([fv.get(k, 0.0) for k in FV])  # mu: `prepare`
        self.state = np.array([NO_WINDOW if fc._c is None else fc._c, fc.n], dtype=np.int64)
        self.acc = np.zeros(N_SUMS)
        self._tables(d, buf)
        self.dropped = 0
        cap = fc.pos.shape[0]
        self.work = np.empty((3, cap, 3))
        self._store = self._pattern = self._sample_kernel = None
        self.z2 = bm.geometry.z2
        self.a = bm.geometry.a

    def _tables(self, d, buf) -> None:
        """run_table's address table over the kernel's current buffers (FlankContacts repacks them when its params
        array is replaced)."""
        fc = self.fc
        k = fc.kernel
        by_name = {  # kept alive here (self.arrays): run_table reads them by address
            "ctrl": d.ctrl,
            "qvel": d.qvel,
            "qpos": d.qpos,
            "act": d.actuator_force,
            "sensordata": d.sensordata,
            "xpos": d.xpos,
            "xmat": d.xmat,
            "fb": k.fb,
            "ib": k.ib,
            "ks": fc.ks,
            "params": fc.params,
            "pos": fc.handed[1],  # pos, depth, weight, frame: what is handed to MuJoCo (FlankContacts.handed)
            "depth": fc.handed[0],
            "weight": fc.handed[3],
            "frame": fc.handed[2],
            "records": buf.bytes.view(np.int64),
            "rec_off": buf.off,
            "solref": fc.solref,
            "solreffriction": fc.solreffriction,
            "state": self.state,
            "acc": self.acc,
            "stages": np.concatenate([STAGE_ADDRESSES, [_MJ_ADD_CONTACT]]).astype(np.int64),
            "iv": self.iv,
            "fv": self.fv,
            "mfric": k.mfric,
        }
        self.arrays = tuple(by_name[name] for name, _, _ in TABLE)
        self.table = address_table(self.arrays)
        self._kernel = k

    def prepare(self) -> np.ndarray:
        """run_table's address table with the contacts' current friction (before each call)."""
        fc = self.fc
        if fc.params is not fc.kernel.P:  # replaced: FlankContacts.find would repack (flank_step)
            fc._pack()
        if fc.kernel is not self._kernel:
            self._tables(self.d, fc.buffer)
        self.iv[IV.friction_rows] = fc.solreffriction[1] != 0.0
        self.fv[FV.mu] = fc.mu
        return self.table

    def sync(self) -> None:
        """fc.n and fc's window from the loop's state (after each call)."""
        self.fc.n = int(self.state[1])
        self.fc._c = int(self.state[0])

    def run(self, cmd: np.ndarray, load: np.ndarray, j0: int, j1: int) -> np.ndarray:
        """Steps j0..j1-1 of the commands; returns the sums (run_interval's acc); fc.n and fc's window follow."""
        self.dropped += run_table(self.prepare(), self.m._address, self.d._address, cmd, load, j0, j1)
        self.sync()
        return self.acc

    def sample_table_for(self, pattern, store: tuple) -> np.ndarray:
        """sample_table's address table over the run's arrays (rebuilt when one of them was replaced)."""
        fc = self.fc
        if self._store is not store or self._pattern is not pattern or self._sample_kernel is not fc.kernel:
            cv = pattern.cv
            pts, forces, pts_world = store
            by_name = {"meta": fc.meta, "weight": fc.weight, "depth": fc.depth, "params": fc.params, "work": self.work}
            by_name.update(inv_rho=cv.inv_rho, line_len=cv.line_len, pts=pts, forces=forces, pts_world=pts_world)
            self._sample_arrays = tuple(by_name[name] for name, _, _ in SAMPLE_TABLE)
            self._sample_T = address_table(self._sample_arrays, SAMPLE_TABLE)
            self._store, self._pattern, self._sample_kernel = store, pattern, fc.kernel
        return self._sample_T

    def sample(self, i: int, pattern, rlog, store: tuple):
        """The runner's per-sample contact outputs at sample i (module docstring): writes row i of store = (points in
        tooth 0's frame, forces on the wheel, points; float32, up to their second dimension), the pattern's rows and
        the radius log's (contact_sums.RadiusLog); returns (teeth touching, largest penetration, F_r,lc, contact
        radius)."""
        fc, d = self.fc, self.d
        n = fc.n
        pattern.reserve(n)
        rlog.reserve(n)
        T = self.sample_table_for(pattern, store)
        con = d.contact
        own = self.dropped == 0  # d.contact's last fc.n entries are the kernel's contacts, in order
        # the template's dim 3 (set_friction); efc_address as a contiguous int64 copy, run_samples' type (one
        # compiled signature of sample_table)
        adr, efc, ncon, cone3 = con.efc_address.astype(np.int64), d.efc_force, d.ncon, fc.mu > 0
        if fc.merge:  # the merged contacts' forces split over the slices (FlankContacts.slice_rows)
            adr, efc, _, _, cone3 = fc.slice_rows(d)
            ncon = n = len(adr)
            own = True
        nteeth, pen, fr, W, wr, pattern.m, rlog.m = sample_table(
            T,
            adr,
            fc.frame if own else con.frame,
            fc.pos if own else con.pos,
            own,
            efc,
            pattern.buf,
            rlog.buf,
            ncon,
            n,
            cone3,
            float(d.qpos[fc.qa2]),
            self.z2,
            self.a,
            i,
            pattern.e_star,
            pattern.m,
            rlog.m,
        )
        return nteeth, float(pen), fr, radius_mean(W, wr)
