"""The exact-flank runner's record intervals compiled together: one numba call runs many samples, each
`flank_loop.run_table` (the interval's steps) and then the runner's per-sample work of wormsim.contact3d.runner, so
the per-sample Python (~45-60 us a sample: dispatch, guards, the series column) is paid once per call.

Per sample, in the runner's order and with its floating-point operations (bit-identical series, pattern and radius
logs, contact points: tests/test_flank_samples.py): the steps; the state read from d (shaft angles and speeds,
d.time); the runner's Guards.state checks (non-finite state or MuJoCo's bad-qacc warning, overspeed, teeth jumped);
mu from the friction law (wormsim.physics.friction.friction_coefficient_scalar's three forms); flank_loop.sample_flanks
(with
displaced poses, errors: or shafts:, the points go into tooth 0's frame through the displaced wheel body's frame);
the penetration and lock checks of Guards.contact; the shafts' log (ShaftLog.record: mj_rnePostConstraint by address
where a bearing is rigid, then its raw values, wormsim.contact3d.shafts.gather); the series column (series.SERIES
order).

Anything else hands the sample back to the runner's Python path, after its steps and before any of its per-sample
work: a guard that would act (it raises or keeps state: a stuck drive, the friction guard's next check), a friction
coefficient that starts or stops being zero (FlankContacts.set_friction changes the cone's dimension; other changes
are written into the hand-off's records here, as set_template leaves them), a contact log that needs room, contacts
MuJoCo did not take.
The runner then does that sample (runner._sample), so errors and their messages are the Python guards' own.

d's scalar fields (time, ncon, nefc) and arena pointers (contact, efc_force) are read at their byte offsets in
mjData, from MuJoCo's declared layout and checked once per process (wormsim.contact3d.mjdata_layout: an unknown
layout raises, naming the MuJoCo version).
"""

from __future__ import annotations

import ctypes
import enum
import math

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

from wormsim.contact3d.flank_handoff import _library
from wormsim.contact3d.flank_loop import (
    FV,
    Row,
    SampleRow,
    _call_stage,
    _f1,
    _f64_at,
    _i1,
    _i64_at,
    _records,
    run_table,
    sample_table,
)
from wormsim.contact3d.friction_law import mu_at, stuck_after
from wormsim.contact3d.guards import PENETRATED, RUNNING, STUCK, contact_event, state_event
from wormsim.contact3d.mjdata_layout import mjdata_offsets
from wormsim.contact3d.series import column
from wormsim.contact3d.shafts import gather
from wormsim.tooth.merge import split_forces

ENABLED = True  # the runner's switch (tests compare against the per-sample path)
ADR_CAP = 4096  # contacts per step the compiled sample reads (more: the sample goes to the Python path)

# io: what run_samples hands back
IO_NEXT, IO_PENDING, IO_TURN_MAX, IO_PM, IO_RM, IO_DROPPED, IO_EVENT = range(7)
# io[IO_EVENT]: why run_samples handed a sample back to the runner's Python path (0: it did not)
EV_NONE, EV_GUARD, EV_FRICTION_CHECK, EV_CONE, EV_LOG_FULL, EV_DROPPED = range(6)
# g (float parameters): their names in row order, the one declaration of g's layout
G_NAMES = (
    "dt",
    "direction",
    "ratio",
    "overspeed_turn",
    "jump_rad",
    "pen_lim",
    "lock_start",
    "lock_fraction",
    "next_check",
    "r1",
    "cos_gamma",
    "mu_kind",  # 0 constant, 1 STEP(static, dynamic), 2 friction group
    "mu_a",
    "mu_b",
    "mu_c",
    "mu",  # the coefficient the contacts carry now (FlankContacts.mu)
    "rpm",  # (rad/s) per rpm
    "a",
    "e_star",
    "speed_driven",
    "locked",  # the lock guard holds state (locked_since set)
    "worm_is_drive",
    "qa1",
    "qa2",
    "dof1",
    "dof2",
    "z2",
    "deg",
    "stick_v",  # the friction law's stick state: v_stick (Prepared.stick_velocity_m_s; 0: none)
    "stuck",  # and the state (1.0 stuck)
)
G = enum.IntEnum("G", G_NAMES, start=0)  # g's rows by name: g[G.dt] (numba reads the members as constants)


@intrinsic
def _i32_at(typingctx, addr):
    """The int32 pointer at an address (int64)."""
    sig = types.CPointer(types.int32)(types.int64)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(types.CPointer(types.int32)))

    return sig, codegen


@numba.njit(cache=True, inline="always")
def _set_friction(T, mu):
    """FlankContacts.set_friction where the cone's dimension stays: mu into the loop's fv and the hand-off's records
    (both friction entries), as set_template leaves them."""
    _f1(T, Row.fv)[FV.mu] = mu
    recs = _records(T)
    o5 = _i1(T, Row.rec_off)[5]
    for r in range(recs.shape[0]):
        recs[r, o5] = mu
        recs[r, o5 + 1] = mu


@numba.njit(cache=True, nogil=True)
def run_samples(
    T, Ts, m_addr, d_addr, cmd, load, i0, i1, o0, rec, S, g, off, frame, pos, adr, pat_buf, r_buf, io, mrg, shaft
):
    """Samples i0..i1-1 (module docstring); sample i's steps are o0 + (i - i0) rec .. + rec of cmd and load.
    T, Ts: flank_loop's run and sample tables; S the series (series.SERIES rows); g the parameters (G_NAMES); off
    the checked mjData offsets (wormsim.contact3d.mjdata_layout); frame, pos the kernel's contacts; adr (ADR_CAP) work
    room; pat_buf, r_buf the pattern's and the radius log's rows; io: IO_* (io[IO_PM], io[IO_RM] the logs' rows used
    on entry); mrg: with one contact per tooth flank (merge) the kernel's (grp, share, mfric, mwrap) and the per-slice
    rows' room (FlankContacts.slice_rows), else None; shaft = (mj_rnePostConstraint's address or 0, the shaft log's
    raw addresses, its raw rows: wormsim.contact3d.shafts.ShaftLog), the addresses empty without `shafts:`."""
    rne, sh_adr, sh_raw = shaft
    acc = _f1(T, Row.acc)
    state = _i1(T, Row.state)
    qpos, qvel = _f1(T, Row.qpos), _f1(T, Row.qvel)
    depth = _f1(Ts, SampleRow.depth)
    ib = _i1(T, Row.ib)
    qa1, qa2, dof1, dof2 = int(g[G.qa1]), int(g[G.qa2]), int(g[G.dof1]), int(g[G.dof2])
    dt, direction, ratio = g[G.dt], g[G.direction], g[G.ratio]
    turn_lim, jump_rad, pen_lim = g[G.overspeed_turn], g[G.jump_rad], g[G.pen_lim]
    tptr = _f64_at(d_addr + off[0])
    nptr = _i32_at(d_addr + off[1])
    eptr = _i32_at(d_addr + off[2])
    cptr = _i64_at(d_addr + off[3])
    fptr = _i64_at(d_addr + off[4])
    bptr = _i32_at(d_addr + off[5])
    size, o_adr = off[6], off[7]
    mu_now = g[G.mu]
    cone3 = mu_now > 0.0
    turn_max = io[IO_TURN_MAX]
    pm, rm = int(io[IO_PM]), int(io[IO_RM])
    z2 = int(g[G.z2])
    io[IO_PENDING] = 0.0
    io[IO_EVENT] = EV_NONE
    for i in range(i0, i1):
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
        th1, th2 = qpos[qa1], qpos[qa2]
        w1, w2 = qvel[dof1], qvel[dof2]
        t = tptr[0]
        event, te, turn = state_event(th1, th2, w1, w2, bptr[0], dt, turn_lim, direction, ratio, jump_rad)
        if event != 0:  # Guards.state raises: the Python path
            io[IO_EVENT] = EV_GUARD
            return
        if t > g[G.next_check]:  # the friction guard's next check
            io[IO_EVENT] = EV_FRICTION_CHECK
            return
        vs = abs(w1) * g[G.r1] / g[G.cos_gamma]
        stuck = stuck_after(g[G.stuck] != 0.0, vs, g[G.stick_v])  # idempotent: a hand-back repeats it
        g[G.stuck] = 1.0 if stuck else 0.0
        mu = mu_at(0.0 if stuck else vs, g[G.mu_kind], g[G.mu_a], g[G.mu_b], g[G.mu_c], g[G.deg])
        if mu != mu_now:  # FlankContacts.set_friction: the records' friction, where the cone's dimension stays
            if (mu > 0.0) != (mu_now > 0.0):  # the cone's dimension changes (FlankContacts.set_friction)
                io[IO_EVENT] = EV_CONE
                return
            _set_friction(T, mu)
            mu_now = mu
            g[G.mu] = mu
        # the sample's contacts: d.contact's efc addresses, the largest penetration (Guards.contact's first check)
        ncon = nptr[0]
        n_fc = state[1]
        if ncon > adr.shape[0] or pm + n_fc > pat_buf.shape[0] or rm + n_fc > r_buf.shape[0]:
            io[IO_EVENT] = EV_LOG_FULL
            return
        n = n_fc if mrg is not None else min(n_fc, ncon)
        pen = 0.0
        if n > 0:
            pen = depth[0]
            for c in range(1, n):
                if depth[c] > pen:
                    pen = depth[c]
        w_drive = w1 if g[G.worm_is_drive] != 0.0 else w2
        event = contact_event(
            t, pen, pen_lim, w_drive, cmd_i, g[G.speed_driven] != 0.0, g[G.lock_start], g[G.lock_fraction]
        )
        if event == PENETRATED or event == STUCK or (event == RUNNING and g[G.locked] != 0.0):
            io[IO_EVENT] = EV_GUARD  # Guards.contact raises, or the lock guard acts or keeps state
            return
        cbase = cptr[0]
        for k in range(ncon):
            adr[k] = _i32_at(cbase + k * size + o_adr)[0]
        efc = numba.carray(_f64_at(fptr[0]), (max(eptr[0], 0),))
        # the contacts' rows (FlankContacts.slice_rows), typed as FlankLoop.sample passes them (one compiled
        # signature of sample_table: int64 counts, a non-literal bool)
        a_s, e_s, nc, c3 = adr[:ncon], efc, np.int64(ncon), cone3
        if mrg is not None:  # one contact per tooth flank: the merged contacts' forces split over their slices
            grp, share, mfric, mwrap, adr_m, efc_m = mrg
            nh = min(ib[7], ncon)
            split_forces(adr[:ncon], efc, ncon - nh, cone3, grp, share, mfric, mwrap, n_fc, adr_m, efc_m)
            a_s, e_s, nc, c3 = adr_m[:n_fc], efc_m, n_fc, True
        own = dropped == 0  # True here: d.contact's last entries are the kernel's contacts
        nteeth, pen2, fr, W, wr, pm, rm = sample_table(
            Ts, a_s, frame, pos, own, e_s, pat_buf, r_buf, nc, n_fc, c3, th2, z2, g[G.a], i, g[G.e_star], pm, rm
        )
        if rne != 0:  # ShaftLog.record: the reactions, then the raw values
            _call_stage(rne, m_addr, d_addr)
        gather(sh_adr, sh_raw, i)
        turn_max = max(turn_max, turn)
        r_c = wr / W if W > 0 else math.nan
        sums = (acc[0], acc[1], acc[2], acc[3], acc[4], acc[5], acc[6], acc[7], acc[8], acc[9])
        col = column(t, th1, th2, w1, w2, cmd_i, sums, rec, nteeth, pen2, mu, te, fr, r_c, g[G.rpm])
        for k in range(len(col)):
            S[k, i] = col[k]
        io[IO_PENDING] = 0.0
    io[IO_NEXT] = i1
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
        g = np.zeros(len(G_NAMES))
        g[G.dt] = guards.dt
        g[G.direction] = bm.direction
        g[G.ratio] = geo.ratio
        g[G.overspeed_turn] = guards.turn_lim
        g[G.jump_rad] = guards.jump_rad
        g[G.pen_lim] = guards.pen_lim
        g[G.lock_start] = guards.lock_start
        g[G.lock_fraction] = gt.LOCK_SPEED_FRACTION
        g[G.r1] = geo.r1
        g[G.cos_gamma] = math.cos(geo.gamma)
        kind, a, b, c_, deg = bm.plan.mu_params
        g[G.mu_kind], g[G.mu_a], g[G.mu_b], g[G.mu_c] = kind, a, b, c_
        g[G.deg] = deg
        g[G.stick_v] = bm.plan.stick_velocity_m_s
        g[G.rpm] = RPM
        g[G.a] = geo.a
        g[G.speed_driven] = float(guards.speed_driven)
        g[G.worm_is_drive] = float(bm.plan.drive_on == "worm")
        g[G.qa1], g[G.qa2] = fc.qa1, fc.qa2
        g[G.dof1], g[G.dof2] = bm.worm_dof, bm.wheel_dof
        g[G.z2] = geo.z2
        self.g = g
        self.adr = np.zeros(ADR_CAP, dtype=np.int64)
        self.io = np.zeros(IO_EVENT + 1)
        self._store = store
        rne = _library().mj_rnePostConstraint if slog is not None and slog.reactions else None
        rne_fn = 0 if rne is None else ctypes.cast(rne, ctypes.c_void_p).value
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
        loop, fc, g, io, guards = self.loop, self.fc, self.g, self.io, self.guards
        T = loop.prepare()
        k = fc.kernel
        Ts = loop.sample_table_for(pattern, self._store)
        g[G.next_check] = guards.friction.next_check
        g[G.mu] = fc.mu
        g[G.e_star] = pattern.e_star
        g[G.locked] = float(guards.locked_since is not None)
        g[G.stuck] = float(guards.stuck)
        io[IO_TURN_MAX], io[IO_PM], io[IO_RM] = guards.turn_max, pattern.m, rlog.m
        run_samples(
            T,
            Ts,
            loop.m._address,
            loop.d._address,
            cmd,
            load,
            i0,
            i1,
            o0,
            self.rec,
            self.S,
            g,
            self.off,
            fc.frame,
            fc.pos,
            self.adr,
            pattern.buf,
            rlog.buf,
            io,
            (k.grp, k.share, k.mfric, k.mwrap, fc._adr, fc._efc) if fc.merge else None,
            self.shaft,
        )
        loop.sync()
        if g[G.mu] != fc.mu:  # changed in the call (run_samples): as FlankContacts.set_friction leaves it
            fc.mu = float(g[G.mu])
            fc.template.friction = [fc.mu, fc.mu, 0.0, 0.0, 0.0]
        loop.dropped += int(io[IO_DROPPED])
        guards.turn_max = float(io[IO_TURN_MAX])
        guards.stuck = bool(g[G.stuck] != 0.0)
        pattern.m, rlog.m = int(io[IO_PM]), int(io[IO_RM])
        return int(io[IO_NEXT]), int(io[IO_EVENT])
