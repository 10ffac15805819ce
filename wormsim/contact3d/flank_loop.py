"""The exact-flank step loop compiled: the steps of one record interval of wormsim.contact3d.runner in one
numba call, MuJoCo's C stage functions called by address.

`flank_step` is the one compiled step: MuJoCo's stage list (wormsim.contact3d.native.STEP) by address, with the
flank contacts in its ADD_CONTACTS slot (`add_flanks`: the window update of FlankContacts.window, with assembly errors
flank_pose.set_pose, kernel.find_packed (find_contacts with its memo, slice_weights, contact_frames),
flank_handoff.fill_add). It does what `FlankContacts.step` (wormsim.contact3d.flank_step) does from Python, in the
same order and with the same floating-point operations, so the results are bit-identical
(tests/contact3d/test_flank_loop.py).
`run_table` steps an interval: per step the drive (under its peak torque, gear_theory.servo_command) and load commands
into d.ctrl, the shaft speeds read, flank_step,
then the runner's per-step sums (actuator torques, shaft powers T w, the contact sensor's count, force and moment,
the peak |F_x|).

The stages are the functions of the shared library the mujoco package loaded (wormsim.contact3d.native), called
through their addresses; all are `void f(const mjModel*, mjData*)`. What this skips of
the Python binding is its error interception: an mju_error inside a stage (MuJoCo's fatal errors, e.g. its arena
exhausted) is not turned into a Python exception here. MuJoCo's warnings (d.warning) are counted as before, and the
runner's guards read them after each interval.

`sample` is the runner's per-sample work on the flank contacts in one compiled call (`sample_flanks`, which
flank_samples.run_samples calls too): contact_sums.contact_forces (forces, points, teeth touching; with displaced
poses the points via the displaced wheel body's frame), the largest penetration, hertz.pattern_rows (the contact
pattern's rows), contact_sums.radial_and_radius, and the points stored into the run's arrays.

Both take their per-run arrays as one table of addresses and shapes (`run_table`, `sample_table`: numba's unboxing of
~30 arrays cost 10-20 us per call), viewed as named records (StepViews, ContactRows). Flank runs turn MuJoCo's islands
off (`FlankLoop`: two dofs, one island; measured bit-identical). Cost and checks: docs/contact3d.md, "Exact
flanks: the step loop compiled" (the Python loop spent about 1.3-3.5 us per stage call on the binding and 10-20
us per step on the runner's per-step reads and sums).
"""

from __future__ import annotations

import enum
from typing import NamedTuple

import mujoco
import numba
import numpy as np

from wormsim.contact3d.contact_sums import contact_forces, radial_and_radius, radius_mean
from wormsim.contact3d.flank_handoff import Handed, Handoff, fill_add
from wormsim.contact3d.native import N_BEFORE, call_stage, f1, f2, f3, f32x3, f64_at, i1, stage_addresses
from wormsim.contact3d.series import N_SUMS, add_step
from wormsim.physics import gear_theory as gt
from wormsim.tooth.hertz import pattern_rows
from wormsim.tooth.kernel import find_packed
from wormsim.tooth.pose import set_pose
from wormsim.tooth.window import window_centre

NO_WINDOW = np.iinfo(np.int64).min  # the window's first centre is not set yet
# the step's integer and float parameters (FlankLoop.iv, FlankLoop.fv): the rows by name, the one declaration
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
FV = enum.IntEnum("FV", ("tooth0", "pitch", "margin", "taper", "mu", "servo_band"), start=0)
STAGE_ADDRESSES = stage_addresses()  # native.STEP by address, mj_addContact last


class StepViews(NamedTuple):
    """What flank_step reads and writes, viewed from the address table (`views`)."""

    fns: np.ndarray  # STAGE_ADDRESSES
    qpos: np.ndarray  # d.qpos
    xpos: np.ndarray  # d.xpos
    xmat: np.ndarray  # d.xmat
    iv: np.ndarray  # the integer parameters (IV)
    fv: np.ndarray  # the float parameters (FV: tooth 0's angle, the pitch angle, margin, taper, mu)
    state: np.ndarray  # (the window's centre tooth, the last step's contact count)
    fb: np.ndarray  # the kernel's buffers (flanks.PackedKernel: fb, ib) and ks (the window's teeth, a view of ib)
    ib: np.ndarray
    ks: np.ndarray
    params: np.ndarray  # the kernel's P (a view of fb)
    out: Handed  # FlankContacts.handed (the merged ones with one contact per tooth flank, wormsim.tooth.merge)
    hand: Handoff  # the records (flank_handoff.ContactBuffer) and the law's solref


@numba.njit(cache=True)
def add_flanks(v, m_addr, d_addr):
    """FlankContacts.add compiled (module docstring) on StepViews v; returns the number of contacts MuJoCo did not
    take (arena full)."""
    iv, fv, state, ks, qpos = v.iv, v.fv, v.state, v.ks, v.qpos
    W, pitch = iv[IV.window_teeth], fv[FV.pitch]
    th1, th2 = qpos[iv[IV.worm_qpos]], qpos[iv[IV.wheel_qpos]]
    if iv[IV.displaced]:
        set_pose(v.params, v.xpos, v.xmat, iv[IV.worm_body], iv[IV.wheel_body], th1)
    cw = window_centre(th2, fv[FV.tooth0], pitch)
    if cw != state[0]:
        h = W // 2
        for i in range(W):
            ks[i] = cw - h + 1 + i
        state[0] = cw
    ib = v.ib
    n = find_packed(v.fb, ib, th1, th2, fv[FV.margin], fv[FV.taper])
    state[1] = n
    nh = ib[7] if ib[6] != 0 else n  # one contact per tooth flank (wormsim.tooth.merge): out holds the merged ones
    if nh == 0:
        return 0
    k = min(nh, v.hand.records.shape[0])
    fns = v.fns
    added = fill_add(
        fns[fns.shape[0] - 1], m_addr, d_addr, v.hand, k, v.out, fv[FV.mu], iv[IV.friction_rows] != 0, ib[6] != 0
    )
    return k - added


@numba.njit(cache=True)
def flank_step(v, m_addr, d_addr):
    """One step: native.STEP's stages by address, the flank contacts (add_flanks) in its ADD_CONTACTS slot; returns
    the number of contacts MuJoCo did not take."""
    fns = v.fns
    for s in range(N_BEFORE):
        call_stage(fns[s], m_addr, d_addr)
    dropped = add_flanks(v, m_addr, d_addr)
    for s in range(N_BEFORE, fns.shape[0] - 1):
        call_stage(fns[s], m_addr, d_addr)
    return dropped


@numba.njit(cache=True, nogil=True)
def step_table(T, m_addr, d_addr):
    """One flank_step on the address table T (FlankContacts.step)."""
    return flank_step(views(T), m_addr, d_addr)


# the arrays of the step in FlankLoop's address table: (name, dtype, ndim) per row, in row order; the one
# declaration of the table's layout (Row: the rows by name, for `views` and FlankLoop's arrays)
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
    ("records", "i8", 2),  # the hand-off's records (as int64 rows; viewed as float64)
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
def records(T):
    """The hand-off's records: int64 rows of the same bytes, viewed as float64."""
    return numba.carray(f64_at(T[Row.records, 0]), (T[Row.records, 1], T[Row.records, 2]))


@numba.njit(cache=True, inline="always")
def views(T):
    """StepViews of the address table T (one row per TABLE entry, (address, shape))."""
    R = Row
    iv = i1(T, R.iv)
    out = Handed(f1(T, R.depth), f2(T, R.pos), f2(T, R.frame), f1(T, R.weight), f1(T, R.mfric))
    base, size = iv[IV.record_base], iv[IV.record_size]
    hand = Handoff(records(T), base, size, i1(T, R.rec_off), f1(T, R.solref), f1(T, R.solreffriction))
    return StepViews(
        i1(T, R.stages), f1(T, R.qpos), f2(T, R.xpos), f2(T, R.xmat), iv, f1(T, R.fv), i1(T, R.state),
        f1(T, R.fb), i1(T, R.ib), i1(T, R.ks), f1(T, R.params), out, hand,
    )  # fmt: skip


# the speed servo's command under its peak torque (wormsim.physics.gear_theory.servo_command), compiled into run_table
servo_command = numba.njit(cache=True, inline="always")(gt.servo_command)


@numba.njit(cache=True, nogil=True)
def run_table(T, m_addr, d_addr, cmd, load, j0, j1):
    """Steps j0..j1-1 of the command arrays cmd (drive) and load (module docstring), their arrays given by address
    and shape (T: one row per TABLE entry; numba unboxes one array instead of 30 per call, about 10-20 us per call
    saved, docs/contact3d.md). T's acc (series.SUMS) receives the sums over the steps (series.add_step). Returns the
    number of contacts MuJoCo did not take (arena full) summed over the steps. Releases the GIL, as MuJoCo's
    bindings do around mj_step: wormsim.run imports the report's libraries meanwhile."""
    v = views(T)
    ctrl, qvel, act, sd = f1(T, Row.ctrl), f1(T, Row.qvel), f1(T, Row.act), f1(T, Row.sensordata)
    iv = v.iv
    ia_drv, ia_load, dof1, dof2 = iv[IV.drive_actuator], iv[IV.load_actuator], iv[IV.worm_dof], iv[IV.wheel_dof]
    a1, a2, s0 = iv[IV.worm_actuator], iv[IV.wheel_actuator], iv[IV.sensor]
    band = f1(T, Row.fv)[FV.servo_band]  # the drive's peak torque / kv (servo_command; 0: none)
    dof_drv = dof2 if ia_drv == a2 else dof1
    sums = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    dropped = 0
    for j in range(j0, j1):
        ctrl[ia_drv] = servo_command(cmd[j], qvel[dof_drv], band)
        ctrl[ia_load] = load[j]
        w1j, w2j = qvel[dof1], qvel[dof2]
        dropped += flank_step(v, m_addr, d_addr)
        sums = add_step(sums, act, sd, a1, a2, s0, w1j, w2j)  # the per-step sums (wormsim.contact3d.series)
    acc = f1(T, Row.acc)
    for k in range(N_SUMS):
        acc[k] = sums[k]
    return dropped


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


class ContactRows(NamedTuple):
    """A sample's contacts as sample_flanks reads them."""

    adr: np.ndarray  # the contacts' efc_address
    efc_force: np.ndarray
    frame: np.ndarray  # the contacts' frames and points, or, where own, the kernel's (the same values:
    pos: np.ndarray  # flank_handoff copies them into the contacts)
    ncon: int
    n_fc: int  # the kernel's contacts (the last n_fc of ncon)
    own: bool
    cone3: bool  # elliptic cone: three rows per contact


@numba.njit(cache=True)
def sample_flanks(rows, kern, pose, i, store, work, pat, rlog):
    """FlankLoop.sample's compiled part (module docstring): rows (ContactRows); kern = the kernel's (meta, weight,
    depth, P) (P: the poses, with assembly errors: contact_sums.contact_forces); pose = (th2, z2, centre distance a);
    store = (points in tooth 0's frame, forces, points; the run's float32 arrays, row i); work (3, cap, 3); pat =
    PatternLog's (inv_rho, line_len, E*, buffer, rows used); rlog = contact_sums.RadiusLog's (buffer, rows used).
    Returns (teeth touching, largest penetration, F_r,lc, sum w, sum w r, the pattern's rows used, the radius log's
    rows used)."""
    adr, efc_force, frame, pos, ncon, n_fc, own, cone3 = rows
    meta, weight, depth, P = kern
    th2, z2, a = pose
    pts, forces, pts_world = store
    inv_rho, line_len, e_star, buf, pm = pat
    rbuf, rm = rlog
    n = min(n_fc, ncon)
    if n == 0:
        return 0, 0.0, -0.0, 0.0, 0.0, pm, rm
    k0 = ncon - n
    f0 = 0 if own else k0
    m, nteeth = contact_forces(adr[k0:], frame[f0:], pos[f0:], efc_force, cone3, meta, th2, z2, work, P)
    pen = depth[0]
    for c in range(1, n):
        if depth[c] > pen:
            pen = depth[c]
    pm = pattern_rows(i, adr[k0:ncon], efc_force, meta, weight, inv_rho, line_len, e_star, buf, pm)
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
def sample_table(T, rows, pose, i, logs):
    """sample_flanks with its per-run arrays given by address and shape (T: one row per SAMPLE_TABLE entry);
    logs = (the pattern's buffer, E*, its rows used, the radius log's buffer, its rows used)."""
    buf, e_star, pm, rbuf, rm = logs
    R = SampleRow
    f32 = (f32x3(T, R.pts), f32x3(T, R.forces), f32x3(T, R.pts_world))
    kern = (f2(T, R.meta), f1(T, R.weight), f1(T, R.depth), f1(T, R.params))
    pat = (f3(T, R.inv_rho), f3(T, R.line_len), e_star, buf, pm)
    return sample_flanks(rows, kern, pose, i, f32, f3(T, R.work), pat, (rbuf, rm))


class FlankLoop:
    """run_table's arguments for one FlankContacts and its MjData (module docstring); `run` steps an interval."""

    def __init__(self, fc, d, drive_actuator: int, load_actuator: int, a1: int, a2: int, sensor_adr: int, runner=True):
        """runner: a run's loop (it turns MuJoCo's islands off); else FlankContacts.step's (the model as it is)."""
        bm, m = fc.bm, fc.bm.model
        self.fc, self.m, self.d = fc, m, d
        # one island: the worm and the wheel are the model's only dofs and the flank contacts couple them, so
        # MuJoCo's island decomposition (mj_island, ~3.5 us per step) only repartitions the same solve (measured
        # bit-identical: docs/contact3d.md, "Exact flanks: the step loop compiled")
        if runner and m.nv == 2:
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
        fv[FV.servo_band] = bm.plan.servo_band_rad_s if runner else 0.0
        self.fv = np.array([fv.get(k, 0.0) for k in FV])  # mu: `prepare`
        self.state = np.array([NO_WINDOW if fc.centre is None else fc.centre, fc.n], dtype=np.int64)
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
            "pos": fc.handed.pos,  # pos, depth, weight, frame: what is handed to MuJoCo (FlankContacts.handed)
            "depth": fc.handed.depth,
            "weight": fc.handed.weight,
            "frame": fc.handed.frame,
            "records": buf.bytes.view(np.int64),
            "rec_off": buf.off,
            "solref": fc.solref,
            "solreffriction": fc.solreffriction,
            "state": self.state,
            "acc": self.acc,
            "stages": STAGE_ADDRESSES,
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
            fc.pack()
        if fc.kernel is not self._kernel:
            self._tables(self.d, fc.buffer)
        self.iv[IV.friction_rows] = fc.solreffriction[1] != 0.0
        self.fv[FV.mu] = fc.mu
        return self.table

    def step(self) -> None:
        """One step (step_table) from fc's window and contact count; they follow."""
        fc = self.fc
        T = self.prepare()
        self.state[0] = NO_WINDOW if fc.centre is None else fc.centre
        self.state[1] = fc.n
        self.dropped += step_table(T, self.m._address, self.d._address)
        self.sync()

    def sync(self) -> None:
        """fc.n and fc's window from the loop's state (after each call)."""
        self.fc.n = int(self.state[1])
        self.fc.centre = int(self.state[0])

    def run(self, cmd: np.ndarray, load: np.ndarray, j0: int, j1: int) -> np.ndarray:
        """Steps j0..j1-1 of the commands; returns the sums (run_table's acc); fc.n and fc's window follow."""
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
        own_rows = (fc.frame, fc.pos) if own else (con.frame, con.pos)
        rows = ContactRows(adr, efc, *own_rows, ncon, n, own, cone3)
        pose = (float(d.qpos[fc.qa2]), self.z2, self.a)
        logs = (pattern.buf, pattern.e_star, pattern.m, rlog.buf, rlog.m)
        nteeth, pen, fr, W, wr, pattern.m, rlog.m = sample_table(T, rows, pose, i, logs)
        return nteeth, float(pen), fr, radius_mean(W, wr)
