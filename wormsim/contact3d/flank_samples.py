"""The exact-flank runner's record intervals compiled together: one numba call runs many samples, each
`flank_loop.run_table` (the interval's steps) and then the runner's per-sample work of wormsim.contact3d.runner, so
the per-sample Python (~45-60 us a sample: dispatch, guards, the series column) is paid once per call.

Per sample, in the runner's order and with its floating-point operations (bit-identical series, pattern and radius
logs, contact points: tests/contact3d/test_flank_samples.py): the steps; the state read from d (shaft angles and speeds,
d.time); the runner's Guards.state checks (non-finite state or MuJoCo's bad-qacc warning, overspeed, teeth jumped;
the friction guard's check every CHECK_EVERY_S, FrictionGuard.check, where it passes: the sliding contacts' friction
aligned with their slip and no misalignment held); mu from the friction law with its stick state
(wormsim.physics.friction.mu_at, stuck_after; a stuck pair's break-away from MuJoCo's rows on the worm's hinge,
wormsim.contact3d.breakaway); flank_loop.sample_flanks (with displaced poses, errors: or shafts:, the points go into
tooth 0's frame through the displaced wheel body's frame); the penetration and lock checks of Guards.contact; the
shafts' log (ShaftLog.record: mj_rnePostConstraint by address where a bearing is rigid, then its raw values,
wormsim.contact3d.shafts.gather); the series column (series.SERIES order).

Anything else hands the sample back to the runner's Python path, after its steps and before any of its per-sample
work: a guard that would act (it raises or keeps state: a stuck drive, a friction guard's check that finds the
friction against the slip or holds a misalignment), a friction
coefficient that starts or stops being zero (FlankContacts.set_friction changes the cone's dimension; other changes
are written into the hand-off's records here, as set_template leaves them), a contact log that needs room, contacts
MuJoCo did not take, a stuck pair with more contacts or constraint rows than hinge_need's room.
The runner then does that sample (runner._sample), so errors and their messages are the Python guards' own.

d's scalar fields (time, ncon, nefc) and arena pointers (contact, efc_force) are read at their byte offsets in
mjData, from MuJoCo's declared layout and checked once per process (wormsim.contact3d.native.mjdata_offsets: an
unknown layout raises, naming the MuJoCo version).

run_samples' constants are one typed record per run (`SampleParams`); what changes between calls (the friction guard's
next check, the contacts' mu, E*, the lock guard's state) and what comes back are the named slots of `io` (IO_*).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from wormsim.contact3d.breakaway import hinge_utilisation
from wormsim.contact3d.flank_loop import FV, ContactRows, Row, SampleRow, records, run_table, sample_table
from wormsim.contact3d.friction_guard import ALIGN_MIN, CHECK_EVERY_S, alignment_rows
from wormsim.contact3d.guards import PENETRATED, RUNNING, STUCK, contact_event, state_event
from wormsim.contact3d.native import address, call_mul, call_stage, f1, f64_at, i1, i32_at, i64_at, mjdata_offsets
from wormsim.contact3d.series import column
from wormsim.contact3d.shafts import gather
from wormsim.physics.friction import MuLaw, mu_at, stuck_after
from wormsim.tooth.kernel import contact_frames
from wormsim.tooth.merge import split_forces

ENABLED = True  # the runner's switch (tests compare against the per-sample path)
ADR_CAP = 4096  # contacts per step the compiled sample reads (more: the sample goes to the Python path)

# io: what changes between calls (in) and what run_samples hands back (out), by slot
# out (IO_TURN_MAX, IO_PM, IO_RM in too)
IO_NEXT, IO_PENDING, IO_TURN_MAX, IO_PM, IO_RM, IO_DROPPED, IO_EVENT = range(7)
# in (IO_MU, IO_STUCK and IO_NEXT_CHECK out too: the contacts' mu, the friction law's stick state and the friction
# guard's next check after the call; IO_ALIGNED: the friction guard holds no misalignment, its `since` is None)
IO_NEXT_CHECK, IO_MU, IO_E_STAR, IO_LOCKED, IO_STUCK, IO_ALIGNED = range(7, 13)
IO_LEN = 13
# io[IO_EVENT]: why run_samples handed a sample back to the runner's Python path (0: it did not)
EV_NONE, EV_GUARD, EV_FRICTION_CHECK, EV_CONE, EV_LOG_FULL, EV_DROPPED, EV_STICK = range(7)


class SampleParams(NamedTuple):
    """run_samples' constants of one run (the guards' limits, the gear, the friction law, the model's addresses)."""

    dt: float
    direction: float
    ratio: float
    overspeed_turn: float
    jump_rad: float
    pen_lim: float
    lock_start: float
    lock_fraction: float
    r1: float
    cos_gamma: float
    mu_law: MuLaw  # wormsim.physics.friction.mu_at's law
    stick_v: float  # the friction law's stick state: v_stick (Prepared.stick_velocity_m_s; 0: none)
    v_slide: float  # the friction guard's slip speed (FrictionGuard.v_min: contact.transition_velocity_m_s)
    rpm: float  # (rad/s) per rpm
    a: float
    speed_driven: bool
    worm_is_drive: bool
    qa1: int
    qa2: int
    dof1: int
    dof2: int
    z2: int


@numba.njit(cache=True, inline="always")
def set_friction(T, mu):
    """FlankContacts.set_friction where the cone's dimension stays: mu into the loop's fv and the hand-off's records
    (both friction entries), as set_template leaves them."""
    f1(T, Row.fv)[FV.mu] = mu
    recs = records(T)
    o5 = i1(T, Row.rec_off)[5]
    for r in range(recs.shape[0]):
        recs[r, o5] = mu
        recs[r, o5 + 1] = mu


@numba.njit(cache=True)
def contact_guard(p, io, t, depth, n, w1, w2, cmd_i):
    """Guards.contact's checks on the largest penetration of depth[:n] and the drive's speed: whether it raises or
    the lock guard acts or keeps state (the sample then goes to the Python path)."""
    pen = 0.0
    if n > 0:
        pen = depth[0]
        for c in range(1, n):
            if depth[c] > pen:
                pen = depth[c]
    w_drive = w1 if p.worm_is_drive else w2
    event = contact_event(t, pen, p.pen_lim, w_drive, cmd_i, p.speed_driven, p.lock_start, p.lock_fraction)
    return event == PENETRATED or event == STUCK or (event == RUNNING and io[IO_LOCKED] != 0.0)


@numba.njit(cache=True)
def contact_rows(d_addr, off, adr, ncon, n_fc, cone3, pts, nh, merged, mrg):
    """The sample's contacts (ContactRows) read from d at the checked offsets off: d.contact's efc addresses into
    adr, d.efc_force; pts = (the kernel's contact frames, points, normals); with merged contacts (merged) their
    frames from the normals (kernel.find_packed leaves them out) and their forces split
    over their slices with mrg's arrays (FlankContacts.slice_rows). Typed as FlankLoop.sample passes them (one
    compiled signature of sample_table: int64 counts, a non-literal bool); mrg is the same tuple of arrays either way
    (one compiled signature here and in run_samples, not one per tuple and None)."""
    frame, pos, nrm = pts
    size, o_adr = off[6], off[7]
    cbase = i64_at(d_addr + off[3])[0]
    for k in range(ncon):
        adr[k] = i32_at(cbase + k * size + o_adr)[0]
    efc = numba.carray(f64_at(i64_at(d_addr + off[4])[0]), (max(i32_at(d_addr + off[2])[0], 0),))
    if merged:
        contact_frames(nrm, n_fc, frame)  # the slices' frames: find_packed leaves them out where it merges
        grp, share, mfric, mwrap, adr_m, efc_m = mrg
        split_forces(adr[:ncon], efc, ncon - min(nh, ncon), cone3, (grp, share, mfric, mwrap), n_fc, (adr_m, efc_m))
        return ContactRows(adr_m[:n_fc], efc_m, frame, pos, n_fc, n_fc, True, True)
    return ContactRows(adr[:ncon], efc, frame, pos, np.int64(ncon), n_fc, True, cone3)


@numba.njit(cache=True, inline="always")
def _read_contacts(d_addr, off, ncon, adr, dims, mus):
    """d's first ncon contacts' efc addresses, dimensions and first friction coefficients (the checked offsets off)
    into adr, dims, mus."""
    size, cbase = off[6], i64_at(d_addr + off[3])[0]
    for k in range(ncon):
        c = cbase + k * size
        adr[k] = i32_at(c + off[7])[0]
        dims[k] = i32_at(c + off[9])[0]
        mus[k] = f64_at(c + off[10])[0]


@numba.njit(cache=True)
def hinge_need(m_addr, d_addr, off, p, hold):
    """breakaway.hinge_utilisation of d's contacts (read at the checked offsets off) on the worm's hinge p.dof1:
    hold = (mj_mulJacVec's address, the unit vector's and the column's addresses, the column, the contacts' efc
    address, dimension and friction rows' room, qfrc_smooth); -1 where the contacts or rows do not fit the room."""
    mul, unit_addr, col_addr, col, adr, dims, mus, smooth = hold
    ncon, nefc = i32_at(d_addr + off[1])[0], i32_at(d_addr + off[2])[0]
    if ncon > dims.shape[0] or nefc > col.shape[0]:
        return -1.0
    _read_contacts(d_addr, off, ncon, adr, dims, mus)
    call_mul(mul, m_addr, d_addr, col_addr, unit_addr)  # the hinge's column of the constraint Jacobian
    efc = numba.carray(f64_at(i64_at(d_addr + off[4])[0]), (max(nefc, 0),))
    return hinge_utilisation(adr, dims, mus, ncon, efc, col, smooth[p.dof1])


@numba.njit(cache=True)
def friction_aligned(d_addr, off, hold, v_min):
    """FrictionGuard.check's reading of d's contacts (read at the checked offsets off into hinge_need's room hold)
    at or above ALIGN_MIN: the check passes; False where it does not, or where the contacts do not fit the room."""
    adr, dims, mus = hold[4], hold[5], hold[6]
    ncon, nefc = i32_at(d_addr + off[1])[0], i32_at(d_addr + off[2])[0]
    if ncon > dims.shape[0]:
        return False
    _read_contacts(d_addr, off, ncon, adr, dims, mus)
    n = max(nefc, 0)
    efc = numba.carray(f64_at(i64_at(d_addr + off[4])[0]), (n,))
    vel = numba.carray(f64_at(i64_at(d_addr + off[11])[0]), (n,))
    cos = alignment_rows(adr[:ncon], dims[:ncon], mus[:ncon], efc, vel, v_min)[0]
    return cos >= ALIGN_MIN


@numba.njit(cache=True)
def stick_mu(mj, off, p, hold, stuck, vs):
    """(the friction law's stick state after the sample at the sliding speed vs, the mu it gives): stuck_after, a
    stuck pair's need from hinge_need (only runs with a stick state are ever stuck); mu -1 where hinge_need's room is
    too small."""
    u = 0.0
    if stuck:
        u = hinge_need(mj[0], mj[1], off, p, hold)
        if u < 0.0:
            return stuck, -1.0
    stuck = stuck_after(stuck, vs, p.stick_v, u)
    law = p.mu_law
    return stuck, mu_at(0.0 if stuck else vs, law.kind, law.a, law.b, law.c)


@numba.njit(cache=True, nogil=True)
def run_samples(tables, mj, cmds, span, S, p, room, io, mrg, shaft):
    """Samples i0..i1-1 of span = (i0, i1, o0, rec) (module docstring); sample i's steps are o0 + (i - i0) rec ..
    + rec of cmds = (drive, load). tables = flank_loop's run and sample tables (T, Ts); mj = (the model's and the
    data's address); S the series (series.SERIES rows); p the run's SampleParams; room = (the checked mjData offsets
    (native.mjdata_offsets), the kernel's contact frames, points and normals, ADR_CAP work room, the pattern's and
    the radius log's rows, hinge_need's room); io: IO_*; mrg: the kernel's (grp, share, mfric, mwrap) and the
    per-slice rows' room (FlankContacts.slice_rows), used with one contact per tooth flank (the kernel's merge flag,
    ib[6]); shaft = (mj_rnePostConstraint's address or 0, the shaft log's raw addresses, its raw rows:
    wormsim.contact3d.shafts.ShaftLog), the addresses empty without `shafts:`."""
    T, Ts = tables
    m_addr, d_addr = mj
    cmd, load = cmds
    i0, i1_, o0, rec = span
    off, frame, pos, nrm, adr, pat_buf, r_buf, hold = room
    rne, sh_adr, sh_raw = shaft
    acc, state, ib = f1(T, Row.acc), i1(T, Row.state), i1(T, Row.ib)
    merged = ib[6] != 0  # one contact per tooth flank (the kernel's merge flag, wormsim.tooth.merge)
    qpos, qvel = f1(T, Row.qpos), f1(T, Row.qvel)
    depth = f1(Ts, SampleRow.depth)
    tptr, nptr, bptr = f64_at(d_addr + off[0]), i32_at(d_addr + off[1]), i32_at(d_addr + off[5])
    ws = off[8] // 4  # one mjWarningStat in int32s (native.FIELDS: BADQPOS, BADQVEL, BADQACC follow each other)
    mu_now = io[IO_MU]
    cone3 = mu_now > 0.0
    turn_max = io[IO_TURN_MAX]
    pm, rm = int(io[IO_PM]), int(io[IO_RM])
    io[IO_PENDING] = 0.0
    io[IO_EVENT] = EV_NONE
    for i in range(i0, i1_):
        o = o0 + (i - i0) * rec
        io[IO_NEXT] = i
        io[IO_TURN_MAX] = turn_max
        io[IO_PM], io[IO_RM] = pm, rm
        dropped = run_table(T, m_addr, d_addr, cmd, load, o, o + rec)
        io[IO_PENDING] = 1.0  # from here on sample i's steps are done
        io[IO_DROPPED] = dropped
        if dropped:
            io[IO_EVENT] = EV_DROPPED  # contacts MuJoCo did not take
            return
        cmd_i = cmd[o + rec - 1]
        th1, th2 = qpos[p.qa1], qpos[p.qa2]
        w1, w2 = qvel[p.dof1], qvel[p.dof2]
        t = tptr[0]
        warned = bptr[0] + bptr[ws] + bptr[2 * ws]
        event, te, turn = state_event(
            th1, th2, w1, w2, warned, p.dt, p.overspeed_turn, p.direction, p.ratio, p.jump_rad
        )
        if event != 0:  # Guards.state raises: the Python path
            io[IO_EVENT] = EV_GUARD
            return
        if t > io[IO_NEXT_CHECK]:  # the friction guard's next check: compiled where it passes with no misalignment
            if io[IO_ALIGNED] == 0.0 or not friction_aligned(d_addr, off, hold, p.v_slide):
                io[IO_EVENT] = EV_FRICTION_CHECK  # FrictionGuard.check keeps state or acts: the Python path
                return
            io[IO_NEXT_CHECK] = t + CHECK_EVERY_S  # as FrictionGuard.check leaves it (since stays None)
        vs = abs(w1) * p.r1 / p.cos_gamma  # the sliding speed Vs
        # the stick state, written back at the sample's end (a hand-back repeats stuck_after), and mu
        stuck, mu = stick_mu(mj, off, p, hold, io[IO_STUCK] != 0.0, vs)
        if mu < 0.0:  # more contacts or rows than hinge_need's room: the Python path
            io[IO_EVENT] = EV_STICK
            return
        if mu != mu_now:  # FlankContacts.set_friction: the records' friction, where the cone's dimension stays
            if (mu > 0.0) != (mu_now > 0.0):  # the cone's dimension changes (FlankContacts.set_friction)
                io[IO_EVENT] = EV_CONE
                return
            set_friction(T, mu)
            mu_now = mu
            io[IO_MU] = mu
        # the sample's contacts: d.contact's efc addresses, the largest penetration (Guards.contact's first check)
        ncon = nptr[0]
        n_fc = state[1]
        if ncon > adr.shape[0] or pm + n_fc > pat_buf.shape[0] or rm + n_fc > r_buf.shape[0]:
            io[IO_EVENT] = EV_LOG_FULL
            return
        if contact_guard(p, io, t, depth, n_fc if merged else min(n_fc, ncon), w1, w2, cmd_i):
            io[IO_EVENT] = EV_GUARD  # Guards.contact raises, or the lock guard acts or keeps state
            return
        rows = contact_rows(d_addr, off, adr, ncon, n_fc, cone3, (frame, pos, nrm), ib[7], merged, mrg)
        logs = (pat_buf, io[IO_E_STAR], pm, r_buf, rm)
        nteeth, pen2, fr, W, wr, pm, rm = sample_table(Ts, rows, (th2, p.z2, p.a), i, logs)
        if rne != 0:  # ShaftLog.record: the reactions, then the raw values
            call_stage(rne, m_addr, d_addr)
        gather(sh_adr, sh_raw, i)
        turn_max = max(turn_max, turn)
        r_c = wr / W if W > 0 else math.nan
        sums = (acc[0], acc[1], acc[2], acc[3], acc[4], acc[5], acc[6], acc[7], acc[8], acc[9])
        col = column((t, th1, th2, w1, w2, cmd_i), sums, rec, (nteeth, pen2, mu, te, fr, r_c), p.rpm)
        for k in range(len(col)):
            S[k, i] = col[k]
        io[IO_STUCK] = 1.0 if stuck else 0.0
        io[IO_PENDING] = 0.0
    io[IO_NEXT] = i1_
    io[IO_TURN_MAX] = turn_max
    io[IO_PM], io[IO_RM] = pm, rm


class FlankSamples:
    """run_samples' parameters for one run (the runner's FlankLoop, guards, friction law, logs); `run` steps and
    samples a stretch of one command block."""

    NONE = EV_NONE  # run's event when the stretch is done

    def __init__(self, loop, guards, bm, rec: int, series: np.ndarray, store: tuple, slog=None):
        """The parameters from the guards and the run's plan (bm.plan: the friction law, the drive's kind); the run's
        series, point store (FlankLoop.sample's) and shaft log (wormsim.contact3d.shafts.ShaftLog, or None)."""
        from wormsim.physics import gear_theory as gt
        from wormsim.physics.units import RPM

        fc, geo = loop.fc, bm.geometry
        self.loop, self.fc, self.guards, self.rec, self.S = loop, fc, guards, rec, series
        self.off = mjdata_offsets()
        self.params = SampleParams(
            dt=guards.dt,
            direction=float(bm.direction),
            ratio=float(geo.ratio),
            overspeed_turn=guards.turn_lim,
            jump_rad=guards.jump_rad,
            pen_lim=guards.pen_lim,
            lock_start=guards.lock_start,
            lock_fraction=gt.LOCK_SPEED_FRACTION,
            r1=float(geo.r1),
            cos_gamma=math.cos(geo.gamma),
            mu_law=bm.plan.mu_law,
            stick_v=float(bm.plan.stick_velocity_m_s),
            v_slide=float(guards.friction.v_min),
            rpm=RPM,
            a=float(geo.a),
            speed_driven=bool(guards.speed_driven),
            worm_is_drive=bm.plan.drive_on == "worm",
            qa1=int(fc.qa1),
            qa2=int(fc.qa2),
            dof1=int(bm.worm_dof),
            dof2=int(bm.wheel_dof),
            z2=int(geo.z2),
        )
        self.adr = np.zeros(ADR_CAP, dtype=np.int64)
        # hinge_need's room: the worm hinge's unit vector, the Jacobian column, the contacts' efc addresses,
        # dimensions and mu
        unit, col = np.zeros(loop.m.nv), np.zeros(8 * ADR_CAP)
        unit[bm.worm_dof] = 1.0
        adrs, dims, mus = np.zeros(ADR_CAP, dtype=np.int64), np.zeros(ADR_CAP, dtype=np.int64), np.zeros(ADR_CAP)
        smooth = loop.d.qfrc_smooth  # a view of d's buffer (not its arena): the same address every step
        self.hold = (address("mj_mulJacVec"), unit.ctypes.data, col.ctypes.data, col, adrs, dims, mus, smooth)
        self._unit = unit  # hold carries only its address
        self.io = np.zeros(IO_LEN)
        self._store = store
        rne_fn = address("mj_rnePostConstraint") if slog is not None and slog.reactions else 0
        if slog is None:
            self.shaft = (0, np.zeros(0, dtype=np.int64), np.zeros((1, 0)))
        else:
            self.shaft = (rne_fn, slog.addresses(loop.d), slog.raw)

    def usable(self) -> bool:
        """The compiled samples apply: every contact MuJoCo's so far."""
        return ENABLED and self.loop.dropped == 0

    def run(self, cmd, load, i0: int, i1: int, o0: int, pattern, rlog) -> tuple[int, int]:
        """Samples i0..i1-1 (run_samples); returns (the next sample, the event: EV_NONE when the stretch is done,
        else why that sample, its steps done, is left to the runner's Python path)."""
        loop, fc, io, guards = self.loop, self.fc, self.io, self.guards
        tables = (loop.prepare(), loop.sample_table_for(pattern, self._store))
        k = fc.kernel
        io[IO_NEXT_CHECK], io[IO_MU], io[IO_E_STAR] = guards.friction.next_check, fc.mu, pattern.e_star
        io[IO_LOCKED] = float(guards.locked_since is not None)
        io[IO_ALIGNED] = float(guards.friction.since is None)
        io[IO_STUCK] = float(guards.stuck)
        io[IO_TURN_MAX], io[IO_PM], io[IO_RM] = guards.turn_max, pattern.m, rlog.m
        room = (self.off, fc.frame, fc.pos, fc.nrm, self.adr, pattern.buf, rlog.buf, self.hold)
        mrg = (k.grp, k.share, k.mfric, k.mwrap, fc.slice_adr, fc.slice_efc)  # read only with merge (run_samples)
        mj = (loop.m._address, loop.d._address)
        run_samples(tables, mj, (cmd, load), (i0, i1, o0, self.rec), self.S, self.params, room, io, mrg, self.shaft)
        loop.sync()
        if io[IO_MU] != fc.mu:  # changed in the call (run_samples): as FlankContacts.set_friction leaves it
            fc.mu = float(io[IO_MU])
            fc.template.friction = [fc.mu, fc.mu, 0.0, 0.0, 0.0]
        loop.dropped += int(io[IO_DROPPED])
        guards.turn_max = float(io[IO_TURN_MAX])
        guards.friction.next_check = float(io[IO_NEXT_CHECK])
        guards.stuck = bool(io[IO_STUCK] != 0.0)
        pattern.m, rlog.m = int(io[IO_PM]), int(io[IO_RM])
        return int(io[IO_NEXT]), int(io[IO_EVENT])
