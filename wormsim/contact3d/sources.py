"""The contact sources of a contact3d run, behind one interface the runner drives (wormsim.contact3d.runner):

    advance(cmd, load, i, i_end, o, rlog) -> (i', sums): sample i's steps o..o+rec-1 of the block's command arrays
        and, where the source compiles its samples, the samples after it up to i_end (exclusive); sums None: the
        samples up to i' are done; else sample i' has its steps done (sums: (T1, T2, P1, P2, contacts, F_x, F_y,
        F_z, M_z, |F_x| peak) over them) and its per-sample work is the runner's,
    sample(i, th2, mu, rlog, store) -> (teeth touching, largest penetration, F_r at the line of centres, contact
                                        radius), with row i of store (points in tooth 0's frame, forces, points),
    finish(S, summary, extra): the source's own summary keys and outputs after the loop.

PieceSource: the convex collision pieces in MuJoCo's own collision (contact.geometry pieces), stepped by mj_step.
FlankSource: the exact flanks (contact.geometry flanks, wormsim.tooth's kernel) handed to MuJoCo between collision and
constraints, stepped and sampled by the compiled loop (wormsim.contact3d.flank_samples, wormsim.contact3d.flank_loop);
its samples come back to the runner only on the compiled loop's events."""

from __future__ import annotations

import functools
import math

import mujoco
import numpy as np

from wormsim.contact3d.mjcf import BuiltModel
from wormsim.contact3d.series import ZERO_SUMS, add_step
from wormsim.contact3d.slots import repose_window
from wormsim.physics import gear_theory as gt

_ROWS3 = np.arange(3)  # the normal and two tangent rows of an elliptic-cone contact


class PieceSource:
    """contact.geometry pieces: MuJoCo's collision of the convex pieces, the wheel's window re-posed per sample."""

    def __init__(self, bm: BuiltModel, d: mujoco.MjData, io: tuple, rec: int):
        """io = (drive actuator, load actuator, worm actuator, wheel actuator, contact sensor address); rec the steps
        per sample."""
        self.bm, self.m, self.d = bm, bm.model, d
        self.io, self.rec = io, rec
        self._block: tuple = (None, [], [])  # the command block's arrays as lists (one conversion per block)
        self.coll = np.concatenate([bm.worm_geoms, bm.wheel_slot_geoms.ravel()])
        self.window = repose_window(bm, 0.0)
        self.mu_set: float | None = None
        mujoco.mj_forward(self.m, d)

    def advance(self, cmd: np.ndarray, load: np.ndarray, i: int, i_end: int, o: int, rlog) -> tuple[int, tuple]:
        """Sample i's steps o..o+rec-1, one mj_step each; the per-step sums of the module docstring
        (wormsim.contact3d.series.add_step: the actuator forces of each step, computed at its start with the speeds
        read before it; the contact sensor's resultant on the wheel)."""
        if self._block[0] is not cmd:
            self._block = (cmd, cmd.tolist(), load.tolist())
        _, cmd_blk, load_blk = self._block
        m, d, bm, rec = self.m, self.d, self.bm, self.rec
        ia_drv, ia_load, a1, a2, s0 = self.io
        sd, act, qv, ctrl = d.sensordata, d.actuator_force, d.qvel, d.ctrl
        dof1, dof2 = bm.worm_dof, bm.wheel_dof
        sums = ZERO_SUMS
        band, dof_drv = bm.plan.servo_band_rad_s, dof1 if bm.plan.drive_on == "worm" else dof2
        for j in range(o, o + rec):
            # the drive's peak torque (gear_theory.servo_command; band 0: none)
            ctrl[ia_drv] = gt.servo_command(cmd_blk[j], float(qv[dof_drv]), band) if band else cmd_blk[j]
            ctrl[ia_load] = load_blk[j]
            w1j, w2j = float(qv[dof1]), float(qv[dof2])
            mujoco.mj_step(m, d)
            sums = add_step(sums, act, sd, a1, a2, s0, w1j, w2j)
        return i, sums

    def sample(self, i: int, th2: float, mu: float, rlog, store: tuple) -> tuple:
        """Re-pose the window, set mu on the pieces, read the contacts (contact_details)."""
        bm = self.bm
        self.window = repose_window(bm, th2, self.window)
        if mu != self.mu_set:
            self.m.geom_friction[self.coll, 0] = self.mu_set = mu
        nteeth, pen, p0, F, pw = contact_details(bm, self.d, self.window)
        fr_lc, r_c = _store_points(i, p0, F, pw, rlog, store, bm.geometry.a)
        return nteeth, pen, fr_lc, r_c

    def finish(self, S: dict, summary: dict, extra: dict) -> None:
        """Nothing of its own."""


class FlankSource:
    """contact.geometry flanks: the exact-flank contacts (wormsim.contact3d.flank_step) in the compiled step loop,
    the contact pattern and Hertz pressure logged per sample (wormsim.tooth.hertz)."""

    def __init__(self, bm: BuiltModel, d: mujoco.MjData, io: tuple, guards, rec: int, S_all, store, slog):
        """io as PieceSource's; the run's guards, series array S_all, point store and shaft log (None without
        `shafts:`), which the compiled samples write."""
        from wormsim.contact3d.flank_loop import FlankLoop
        from wormsim.contact3d.flank_samples import FlankSamples
        from wormsim.contact3d.flank_step import FlankContacts
        from wormsim.contact3d.native import split_forward
        from wormsim.tooth.hertz import PatternLog

        self.bm, self.d = bm, d
        self.fc = fc = FlankContacts(bm, bm.law.contacts_per_pair)
        self.pattern = PatternLog(fc, bm.plan.e_star_pa)
        split_forward(bm.model, d, fc.add)
        self.coll = np.zeros(0, dtype=int)
        self.loop = FlankLoop(fc, d, *io)
        self.fast = FlankSamples(self.loop, guards, bm, rec, S_all, store, slog)
        self.rec = rec

    def advance(self, cmd: np.ndarray, load: np.ndarray, i: int, i_end: int, o: int, rlog) -> tuple[int, tuple | None]:
        """Samples i..i_end-1 compiled (FlankSamples.run): (i_end, None) at the stretch's end, or at an event the
        event's sample with its steps done and their sums. Where the compiled samples do not apply
        (flank_samples.ENABLED off, contacts MuJoCo did not take): sample i's steps alone (FlankLoop.run) and their
        sums."""
        if self.fast.usable():
            i, event = self.fast.run(cmd, load, i, i_end, o, self.pattern, rlog)
            return i, None if event == self.fast.NONE else tuple(self.loop.acc.tolist())
        return i, tuple(self.loop.run(cmd, load, o, o + self.rec).tolist())

    def sample(self, i: int, th2: float, mu: float, rlog, store: tuple) -> tuple:
        """Set mu on the flank contacts; read them (FlankLoop.sample, compiled)."""
        self.fc.set_friction(mu)
        return self.loop.sample(i, self.pattern, rlog, store)

    def finish(self, S: dict, summary: dict, extra: dict) -> None:
        """The loaded contact pattern and Hertz stress over the steady window (wormsim.tooth.hertz)."""
        summary.update(self.pattern.summary(S["t_s"], summary["steady_window_s"]))
        extra["flank_pattern"] = self.pattern.grid(S["t_s"], summary["steady_window_s"])
        extra["flank_pattern_log"] = self.pattern  # its table() per contact and sample (studies/slice_convergence_*)


def _store_points(i: int, p0, F, pw, rlog, store: tuple, a: float) -> tuple[float, float]:
    """Row i of store (up to its width) and the radius log's rows; returns (F_r at the line of centres, radius)."""
    pts, forces, pts_world = store
    k = min(len(p0), pts.shape[1])
    pts[i, :k], forces[i, :k], pts_world[i, :k] = p0[:k], F[:k], pw[:k]
    return rlog.add(i, F, pw, a)


def contact_details(bm: BuiltModel, d: mujoco.MjData, window_ks: np.ndarray):
    """The contacts one by one (the resultant comes from the contact sensor): (n_teeth touching, max penetration,
    points in the frame of wheel tooth 0 (n, 3), forces on the wheel (n, 3) world, points (n, 3) world). Forces are
    the elliptic-cone rows (normal, two tangents: what mj_contactForce returns) turned into the world frame."""
    n = d.ncon
    if n == 0:
        z = np.zeros((0, 3))
        return 0, 0.0, z, z, z
    con = d.contact
    adr = np.asarray(con.efc_address[:n])
    ok = adr >= 0
    geom = np.asarray(con.geom[:n])[ok]
    adr = adr[ok]
    frame = np.asarray(con.frame[:n])[ok].reshape(-1, 3, 3)
    pos = np.asarray(con.pos[:n])[ok]
    dist = np.asarray(con.dist[:n])[ok]
    f = d.efc_force[adr[:, None] + _ROWS3]
    F = np.einsum("ni,nij->nj", f, frame)  # force on geom2, world frame
    wheel_is_2 = bm.model.geom_bodyid[geom[:, 1]] != bm.worm_body
    F = np.where(wheel_is_2[:, None], F, -F)  # force on the wheel
    wheel_geom = np.where(wheel_is_2, geom[:, 1], geom[:, 0])
    # tooth index of each contact: slot -> tooth in the current window
    W = bm.window_teeth
    slots = slot_lookup(bm)[wheel_geom]
    tooth_of_slot = np.zeros(W, dtype=int)
    tooth_of_slot[np.asarray(window_ks) % W] = window_ks
    ks = tooth_of_slot[slots]
    # contact points in tooth-0 frame: undo wheel rotation and tooth angle
    th2 = float(d.qpos[bm.model.jnt_qposadr[bm.model.dof_jntid[bm.wheel_dof]]])
    ang = -(th2 + 2 * math.pi * ks / bm.geometry.z2)
    c, s = np.cos(ang), np.sin(ang)
    p0 = np.stack([c * pos[:, 0] - s * pos[:, 1], s * pos[:, 0] + c * pos[:, 1], pos[:, 2]], axis=1)
    pen = float(max(0.0, -dist.min())) if len(dist) else 0.0
    return int(np.unique(ks).size), pen, p0, F, pos


def slot_lookup(bm: BuiltModel) -> np.ndarray:
    """Geom id -> window slot of the wheel's collision geoms (-1 elsewhere), computed once per model layout."""
    rows = np.ascontiguousarray(bm.wheel_slot_geoms, dtype=np.int64)
    return _slot_table(int(bm.model.ngeom), rows.shape, rows.tobytes())


@functools.lru_cache(maxsize=8)
def _slot_table(ngeom: int, shape: tuple[int, ...], slot_geoms: bytes) -> np.ndarray:
    """The lookup of slot_lookup, keyed by its content: the model's geom count and the slots' geom ids (a sweep
    that runs several scenarios in one process gets each model's own table)."""
    rows = np.frombuffer(slot_geoms, dtype=np.int64).reshape(shape)
    lut = np.full(ngeom, -1, dtype=int)
    for s, row in enumerate(rows):
        lut[row] = s
    lut.flags.writeable = False
    return lut
