"""The exact-flank step loop compiled (issue 13): the steps of one record interval of wormsim.contact3d.runner in one
numba call, MuJoCo's C stage functions called by address.

Each step does what the runner's Python loop did with `FlankContacts.step` (wormsim.contact3d.flank_step), in the
same order and with the same floating-point operations, so the results are bit-identical
(tests/test_flank_loop.py): the drive and load commands into d.ctrl, the shaft speeds read, then `split_step`'s stages
(mj_checkPos, mj_checkVel, mj_fwdKinematics, mj_makeM, mj_factorM, mj_collision; the flank contacts: the window
update of FlankContacts.window, with assembly errors flank_pose.set_pose, flanks.find_contacts, slice_weights,
contact_frames, flank_handoff._fill_add; mj_makeConstraint, mj_island, mj_transmission, mj_projectConstraint,
mj_sensorPos, mj_fwdVelocity, mj_sensorVel, mj_step2), then the runner's per-step sums (actuator torques, shaft
powers T w, the contact sensor's count, force and moment, the peak |F_x|).

The stages are the functions of the shared library the mujoco package loaded (flank_handoff._library), called through
their addresses as flank_handoff calls mj_addContact; all are `void f(const mjModel*, mjData*)`. What this skips of
the Python binding is its error interception: an mju_error inside a stage (MuJoCo's fatal errors, e.g. its arena
exhausted) is not turned into a Python exception here. MuJoCo's warnings (d.warning) are counted as before, and the
runner's guards read them after each interval.

`sample` is the runner's per-sample work on the flank contacts in one compiled call: flank_step.flank_contact_details
(forces, points, teeth touching, largest penetration), flank_outputs.PatternLog.record (the contact pattern's rows),
contact_sums.radial_and_radius, and the points stored into the run's arrays.

Cost (docs/contact3d.md, "Exact flanks: cost"): the Python loop spent about 1.3-3.5 us per stage call on the binding
and 10-20 us per step on the runner's per-step reads and sums.
"""

from __future__ import annotations

import ctypes
import math

import mujoco
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from wormsim.contact3d.contact_sums import radial_and_radius, radius_mean
from wormsim.contact3d.flank_handoff import _MJ_ADD_CONTACT, _fill_add, _library
from wormsim.contact3d.flank_outputs import _rows
from wormsim.contact3d.flank_pose import set_pose
from wormsim.contact3d.flank_step import _contact_forces
from wormsim.contact3d.flanks import contact_frames, find_contacts, slice_weights

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
N_ACC = 10  # the per-interval sums (`run_interval`)
NO_WINDOW = np.iinfo(np.int64).min  # the window's first centre is not set yet


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
def run_interval(fns, m_addr, d_addr, cmd, load, j0, j1, mjd, iv, fv, state, grid, params, out, hand, acc):
    """Steps j0..j1-1 of the command arrays cmd (drive) and load (module docstring).

    mjd = (ctrl, qvel, qpos, actuator_force, sensordata, xpos, xmat): d's own arrays;
    iv = (drive actuator, load actuator, worm dof, wheel dof, worm-shaft actuator, wheel-shaft actuator, contact sensor
    address, worm qpos address, wheel qpos address, worm body, wheel body, displaced, window teeth, slices,
    mjContact record size, record buffer address, solreffriction written);
    fv = (tooth 0's angle, pitch angle, margin, taper); state = (the window's centre tooth, the last step's contact
    count); grid = FlankContacts.grid's (xy, c, c_range, span, zeta) and ks (the window's teeth); out = the kernel's
    (pos, nrm, depth, meta, line, weight, frame); hand = (records, field offsets, solref, solreffriction).
    acc (N_ACC) receives the sums over the steps: worm and wheel actuator torque, worm and wheel power, contact count,
    F_x, F_y, F_z, M_z about the wheel axis, the peak |F_x|. Returns the number of contacts MuJoCo did not take
    (arena full) summed over the steps."""
    ctrl, qvel, qpos, act, sd, xpos, xmat = mjd
    ia_drv, ia_load, dof1, dof2, a1, a2, s0, qa1, qa2, worm_body, wheel_body, displaced, W, slices, size, base, fr = iv
    tooth0, pitch, margin0, taper = fv
    xy, c, c_range, span, zeta, ks = grid
    pos, nrm, depth, meta, line, weight, frame = out
    rec, off, solref, solreffriction = hand
    nb = N_BEFORE
    t1 = t2 = p1 = p2 = nc = fx = fy = fz = mz = fpk = 0.0
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
        n = find_contacts(xy, c, c_range, span, zeta, ks, th1, th2, margin0, params, pos, nrm, depth, meta, line, taper)
        n = slice_weights(meta, line, n, slices, pos, nrm, depth, weight)
        contact_frames(nrm, n, frame)
        state[1] = n
        if n:
            k = min(n, rec.shape[0])
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
            )
            dropped += k - added
        for s in range(nb, fns.shape[0] - 1):
            _call_stage(fns[s], m_addr, d_addr)
        # the runner's per-step sums (wormsim.contact3d.runner.run_model)
        q1, q2 = act[a1], act[a2]
        t1 += q1
        t2 += q2
        p1 += q1 * w1j
        p2 += q2 * w2j
        nc += sd[s0]
        f0, f1, f2 = sd[s0 + 1], sd[s0 + 2], sd[s0 + 3]
        fx += f0
        if abs(f0) > fpk:
            fpk = abs(f0)
        fy += f1
        fz += f2
        mz += sd[s0 + 6] + sd[s0 + 7] * f1 - sd[s0 + 8] * f0
    acc[0], acc[1], acc[2], acc[3], acc[4] = t1, t2, p1, p2, nc
    acc[5], acc[6], acc[7], acc[8], acc[9] = fx, fy, fz, mz, fpk
    return dropped


@numba.njit(cache=True)
def sample_flanks(
    adr, frame, pos, own, efc_force, ncon, n_fc, cone3, meta, weight, depth, th2, z2, a, i, store, work, pat, rlog
):
    """FlankLoop.sample's compiled part (module docstring): adr the contacts' efc_address; frame, pos theirs or,
    where own, the kernel's (the same values: flank_handoff copies them into the contacts); store = (points in tooth
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
    m, nteeth = _contact_forces(adr[k0:], frame[f0:], pos[f0:], efc_force, cone3, meta, th2, z2, work)
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


class FlankLoop:
    """run_interval's arguments for one FlankContacts and its MjData (module docstring); `run` steps an interval."""

    def __init__(self, fc, d, drive_actuator: int, load_actuator: int, a1: int, a2: int, sensor_adr: int):
        bm, m = fc.bm, fc.bm.model
        self.fc, self.m, self.d = fc, m, d
        # one island: the worm and the wheel are the model's only dofs and the flank contacts couple them, so
        # MuJoCo's island decomposition (mj_island, ~3.5 us per step) only repartitions the same solve (measured
        # bit-identical: docs/contact3d.md, "Exact flanks: cost")
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ISLAND)
        self.fns = np.concatenate([STAGE_ADDRESSES, [_MJ_ADD_CONTACT]]).astype(np.int64)
        self.mjd = (d.ctrl, d.qvel, d.qpos, d.actuator_force, d.sensordata, d.xpos, d.xmat)
        buf = fc.buffer
        self.iv = (
            drive_actuator,
            load_actuator,
            bm.worm_dof,
            bm.wheel_dof,
            a1,
            a2,
            sensor_adr,
            fc.qa1,
            fc.qa2,
            bm.worm_body,
            bm.wheel_body,
            int(fc.displaced),
            bm.window_teeth,
            fc.slices,
            buf.size,
            buf.address,
            0,
        )
        self.fv = (float(bm.tooth0_angle_rad), fc.pitch, fc.margin0, fc.taper_rad)
        self.state = np.array([NO_WINDOW if fc._c is None else fc._c, fc.n], dtype=np.int64)
        g = fc.grid
        self.grid = (g.xy, g.c, g.c_range, g.span, g.zeta, fc.ks)
        self.out = (fc.pos, fc.nrm, fc.depth, fc.meta, fc.line, fc.weight, fc.frame)
        self.hand = (buf.rec, buf.off, fc.solref, fc.solreffriction)
        self.acc = np.zeros(N_ACC)
        self.dropped = 0
        cap = fc.pos.shape[0]
        self.work = np.empty((3, cap, 3))
        self.z2 = bm.geometry.z2
        self.a = bm.geometry.a

    def run(self, cmd: np.ndarray, load: np.ndarray, j0: int, j1: int) -> np.ndarray:
        """Steps j0..j1-1 of the commands; returns the sums (run_interval's acc); fc.n and fc's window follow."""
        fc = self.fc
        iv = self.iv
        fr = int(fc.solreffriction[1] != 0.0)
        if iv[-1] != fr:
            self.iv = iv = iv[:-1] + (fr,)
        self.dropped += run_interval(
            self.fns,
            self.m._address,
            self.d._address,
            cmd,
            load,
            j0,
            j1,
            self.mjd,
            iv,
            self.fv,
            self.state,
            self.grid,
            fc.params,
            self.out,
            self.hand,
            self.acc,
        )
        fc.n = int(self.state[1])
        fc._c = int(self.state[0])
        return self.acc

    def sample(self, i: int, pattern, rlog, store: tuple):
        """The runner's per-sample contact outputs at sample i (module docstring): writes row i of store = (points in
        tooth 0's frame, forces on the wheel, points; float32, up to their second dimension), the pattern's rows and
        the radius log's (contact_sums.RadiusLog); returns (teeth touching, largest penetration, F_r,lc, contact
        radius)."""
        fc, d = self.fc, self.d
        n = fc.n
        pattern.reserve(n)
        rlog.reserve(n)
        con = d.contact
        own = self.dropped == 0  # d.contact's last fc.n entries are the kernel's contacts, in order
        nteeth, pen, fr, W, wr, pattern.m, rlog.m = sample_flanks(
            con.efc_address,
            fc.frame if own else con.frame,
            fc.pos if own else con.pos,
            own,
            d.efc_force,
            d.ncon,
            n,
            fc.mu > 0,  # the template's dim 3 (FlankContacts.set_friction)
            fc.meta,
            fc.weight,
            fc.depth,
            float(d.qpos[fc.qa2]),
            self.z2,
            self.a,
            i,
            store,
            self.work,
            (pattern.cv.inv_rho, pattern.cv.line_len, pattern.e_star, pattern.buf, pattern.m),
            (rlog.buf, rlog.m),
        )
        return nteeth, float(pen), fr, radius_mean(W, wr)
