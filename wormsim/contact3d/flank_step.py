"""The exact-flank contacts of one model (wormsim.tooth.kernel) handed to MuJoCo's constraint solver: FlankContacts
finds them and adds them to d.contact in the stage list's ADD_CONTACTS slot (wormsim.contact3d.native.split_step:
between mj_collision and mj_makeConstraint). Validated on a 1 kg box with collision off and the contact added by hand
(tests/contact3d/test_flank_step.py): static normal force = weight, penetration = the solref mapping, sliding
deceleration = mu g.

A contact is added by copying a template mjContact with its per-contact fields (dist, pos, frame, solref) written in
(mj_addContact allocates it in the arena), all of a step's contacts from compiled code in one Python call
(wormsim.contact3d.flank_handoff.fill_add; docs/contact3d.md, "Exact flanks: cost").

Every flank contact is between the worm's visual geom and the wheel's visual geom (contype/conaffinity 0, so MuJoCo
never collides them itself): their bodies give the contact Jacobian, body_invweight0 the contact law's A_hat, and the
model's contact sensor (worm against the wheel's subtree) sees the contacts like collision contacts.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from wormsim.contact3d.contact_sums import contact_forces
from wormsim.contact3d.flank_handoff import ContactBuffer, Handed, fill_add
from wormsim.contact3d.native import MJ_ADD_CONTACT
from wormsim.tooth.grid import flank_grid
from wormsim.tooth.kernel import MARGIN_PITCH, TAPER_SHARE, PackedKernel, contact_frames, find_packed
from wormsim.tooth.merge import split_forces
from wormsim.tooth.window import window_centre


def merge_group(flank_contacts: str | int, slices: int) -> int:
    """The slices per MuJoCo contact for contact.flank_contacts (wormsim.tooth.merge): slice 0 (no merge), tooth
    `slices` (one per tooth flank), N: ceil(slices / N) (N contacts per tooth flank; 0 where that is one slice)."""
    if flank_contacts == "slice":
        return 0
    if flank_contacts == "tooth":
        return slices
    group = -(-slices // int(flank_contacts))
    return group if group > 1 else 0


class FlankContacts:
    """The flank contacts of one model: the grid, the window, the template contact and the step."""

    def __init__(self, bm, slices: int, merge: bool | None = None):
        """merge: one MuJoCo contact per tooth flank (wormsim.tooth.merge; contact.flank_contacts tooth);
        None: from the model's scenario (bm.meta's flank_contacts: slice, tooth or N contacts per tooth flank)."""
        g = bm.geometry
        if merge is None:
            self.group = merge_group(bm.meta.get("flank_contacts", "slice"), slices)
        else:
            self.group = slices if merge else 0
        self.merge = self.group > 0
        m = bm.model
        self.bm = bm
        plan_grid = bm.plan.grid if getattr(bm, "plan", None) is not None else None
        self.grid = plan_grid if plan_grid is not None and plan_grid.slices == slices else flank_grid(g, slices)
        self.pitch = 2 * math.pi / g.z2
        self.margin0 = MARGIN_PITCH * self.pitch + g.backlash / (2 * g.r2)
        self.taper_rad = TAPER_SHARE * self.margin0  # of the error-free window (wormsim.tooth.kernel.find_contacts)
        W = bm.window_teeth
        cap = 2 * W * slices
        self.pos = np.zeros((cap, 3))
        self.nrm = np.zeros((cap, 3))
        self.depth = np.zeros(cap)
        self.meta = np.zeros((cap, 4))
        self.line = np.zeros((cap, 2))
        self.weight = np.zeros(cap)  # each contact's share of its slice (wormsim.tooth.kernel.slice_weights)
        self.slices = slices
        self.frame = np.zeros((cap, 9))
        self.n = 0
        self.qa1 = int(m.jnt_qposadr[m.dof_jntid[bm.worm_dof]])
        self.qa2 = int(m.jnt_qposadr[m.dof_jntid[bm.wheel_dof]])
        self.centre = None
        self.stepper = None  # step's compiled loop (for one MjData)
        self.ks = np.zeros(W, dtype=np.int64)
        worm_geom, wheel_geom = bm.meta.get("flank_geoms", ("worm_visual", "wheel_visual"))  # wormsim.pair: prefixed
        gw = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, worm_geom)
        gg = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, wheel_geom)
        self.geoms = (gw, gg)
        law = bm.law
        t = mujoco.MjContact()
        t.dim = 3
        t.geom = [gw, gg]
        t.geom1, t.geom2 = gw, gg
        t.flex = [-1, -1]
        t.elem = [-1, -1]
        t.vert = [-1, -1]
        t.solref = law.solref
        self.solref = np.asarray(law.solref, dtype=float)
        t.solreffriction = law.solreffriction  # friction rows' own damping, wormsim.contact3d.law (4)
        self.solreffriction = np.asarray(law.solreffriction, dtype=float)
        t.solimp = law.solimp
        t.includemargin = 0.0
        t.exclude = 0
        t.frame = [0, 0, 1, 1, 0, 0, 0, 1, 0]
        self.template = t
        self.mu = None
        self.buffer = None
        self.set_friction(float(m.geom_friction[gw, 0]))
        self.buffer = ContactBuffer(m, t, cap)  # the bulk hand-off (wormsim.contact3d.flank_handoff)
        self.hand = self.buffer.handoff(self.solref, self.solreffriction)
        # with errors: the kernel gets the displaced bodies' poses each step (wormsim.tooth.pose)
        self.params = self.grid.params
        dev = getattr(bm, "deviations", None)
        # poses_from_data: bodies that move on their own (wormsim.contact3d.shafts, wormsim.pair), margin_rad theirs
        self.displaced = (dev is not None and not dev.is_zero()) or bool(bm.meta.get("poses_from_data"))
        if self.displaced:
            from wormsim.tooth import pose as flank_pose

            shift = bm.tooth_shift_rad if bm.tooth_shift_rad is not None else np.zeros(g.z2)
            self.params = flank_pose.displaced_params(self.grid.params, np.asarray(shift, dtype=float))
            self.margin0 += flank_pose.error_margin_rad(g, self.grid, dev) if dev is not None else 0.0
            self.margin0 += float(bm.meta.get("margin_rad", 0.0))
            self._set_pose = flank_pose.set_pose
        self.pack()

    def pack(self) -> None:
        """The kernel's arrays, memo included, in two buffers: one compiled call per step (kernel.find_packed);
        again when self.params was replaced."""
        k = self.kernel = PackedKernel(
            self.grid, self.params, len(self.depth), len(self.ks), self.bm.geometry.z2, self.group
        )
        k.ks[:] = self.ks
        self.pos, self.nrm, self.depth, self.meta, self.line = k.pos, k.nrm, k.depth, k.meta, k.line
        self.weight, self.frame, self.ks, self.params = k.weight, k.frame, k.ks, k.P
        self.memo = (k.memo, k.memo_consts)  # find_contacts' open-slice memo
        k.axes[:] = self._hinges()  # the merge's moment arms (wormsim.tooth.merge)
        # what is handed to MuJoCo: the slice contacts, or one per tooth flank (wormsim.tooth.merge)
        out = (k.mdepth, k.mpos, k.mframe, k.mweight) if self.merge else (k.depth, k.pos, k.frame, k.weight)
        self.handed = Handed(*out, k.mfric)
        self.slice_adr = np.zeros(len(k.depth), dtype=np.int64)  # slice_rows' per-slice rows (merge)
        self.slice_efc = np.zeros(3 * len(k.depth))

    def _hinges(self) -> np.ndarray:
        """(point, direction) of the worm's and the wheel's hinge in the world at qpos0 and the wheel's speed per worm
        speed (the nominal axes: assembly errors move them by their small offsets, not followed here)."""
        m, bm = self.bm.model, self.bm
        d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
        j1, j2 = m.dof_jntid[bm.worm_dof], m.dof_jntid[bm.wheel_dof]
        ratio = float(
            self.grid.params[12]
        )  # the conjugate motion: theta2 = ratio theta1 (wormsim.tooth.kernel._find_contacts)
        return np.concatenate([d.xanchor[j1], d.xaxis[j1], d.xanchor[j2], d.xaxis[j2], [ratio]])

    def n_handed(self) -> int:
        """The number of contacts handed to MuJoCo at the last find (the merged ones with merge)."""
        return int(self.kernel.ib[7]) if self.merge else self.n

    def slice_rows(self, d: mujoco.MjData):
        """Per slice contact (the kernel's last fc.n): (efc_address, efc_force, frame, pos, cone3) to read its
        constraint force from, as d.contact's last fc.n entries give it; with merge, the merged contacts' forces split
        over their slices (merge.split_forces: efc_address into the returned efc_force, three rows each)."""
        dim3 = self.template.dim == 3
        if not self.merge:
            n = min(self.n, d.ncon)
            k0 = d.ncon - n
            con = d.contact
            return con.efc_address[k0:], d.efc_force, con.frame[k0:], con.pos[k0:], dim3
        k = self.kernel
        n = self.n
        nh = min(int(k.ib[7]), d.ncon)
        adr, efc, k0 = self.slice_adr, self.slice_efc, d.ncon - nh
        merged = (k.grp, k.share, k.mfric, k.mwrap)
        split_forces(d.contact.efc_address, d.efc_force, k0, dim3, merged, n, (adr, efc))
        contact_frames(self.nrm, n, self.frame)  # find_packed leaves the slices' frames out where it merges
        return self.slice_adr[:n], self.slice_efc, self.frame[:n], self.pos[:n], True

    def set_friction(self, mu: float) -> None:
        if mu != self.mu:
            # frictionless: a 1-dimensional contact (MuJoCo's elliptic cone with mu = 0 gave no normal force at all)
            self.template.dim = 3 if mu > 0 else 1
            self.template.friction = [mu, mu, 0.0, 0.0, 0.0]
            self.mu = mu
            if self.buffer is not None:
                self.buffer.set_template(self.template)

    def window(self, theta2: float) -> np.ndarray:
        """Tooth indices of the mesh window (wormsim.contact3d.mjcf.window_teeth_at), updated by whole pitches."""
        bm = self.bm
        c = window_centre(theta2, bm.tooth0_angle_rad, self.pitch)
        if c != self.centre:
            h = bm.window_teeth // 2
            self.ks[:] = np.arange(c - h + 1, c - h + 1 + bm.window_teeth)
            self.centre = c
        return self.ks

    def find(self, d: mujoco.MjData) -> int:
        """Run the kernel at the current positions (kernel.find_packed: find_contacts with its memo, slice_weights,
        contact_frames); returns the number of contacts."""
        q = d.qpos  # one view (each d.qpos builds one: ~1 us)
        th1, th2 = q[self.qa1], q[self.qa2]
        if self.params is not self.kernel.P:
            self.pack()
        if self.displaced:
            self._set_pose(self.params, d.xpos, d.xmat, self.bm.worm_body, self.bm.wheel_body, th1)
        self.window(th2)
        k = self.kernel
        self.n = n = find_packed(k.fb, k.ib, th1, th2, self.margin0, self.taper_rad)
        return n

    def add(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """Find the flank contacts and append them to d.contact (after mj_collision), in bulk from compiled code
        (wormsim.contact3d.flank_handoff; `add_loop` is the same from Python, one mj_addContact per contact)."""
        self.find(d)
        n = self.n_handed()
        if n:
            n = min(n, self.buffer.cap)
            fr = self.solreffriction[1] != 0.0
            fill_add(MJ_ADD_CONTACT, m._address, d._address, self.hand, n, self.handed, self.mu, fr, self.merge)

    def add_loop(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """`add` from Python: the template added once per contact, then its fields written through d.contact's views."""
        self.find(d)
        n = self.n_handed()
        if n == 0:
            return
        depth, pos, frame, weight, _ = self.handed
        k0 = d.ncon
        t = self.template
        for _ in range(n):
            if mujoco.mj_addContact(m, d, t):
                break  # arena full: MuJoCo warns (mjWARN_CONTACTFULL)
        k1 = d.ncon
        c = d.contact
        c.dist[k0:k1] = -depth[: k1 - k0]
        c.pos[k0:k1] = pos[: k1 - k0]
        c.frame[k0:k1] = frame[: k1 - k0]
        # each contact's stiffness and damping scaled by its share of its slice (direct solref: -k, -b)
        c.solref[k0:k1] = np.multiply.outer(weight[: k1 - k0], self.solref)
        wf = weight[: k1 - k0]
        if self.merge:  # friction mu / c_w and its damping by W (wormsim.tooth.merge)
            fs = self.kernel.mfric[: k1 - k0]
            wf = wf * fs
            c.friction[k0:k1, 0] = c.friction[k0:k1, 1] = self.mu * fs
        if self.solreffriction[1] != 0.0:
            c.solreffriction[k0:k1] = np.multiply.outer(wf, self.solreffriction)

    def step(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """One step of m (this model) on d: native.STEP with the flank contacts, the compiled step
        (wormsim.contact3d.flank_loop.flank_step); `native.split_step(m, d, self.add)` is the same from Python."""
        from wormsim.contact3d.flank_loop import FlankLoop  # flank_loop builds on this module

        if self.stepper is None or self.stepper.d is not d:
            self.stepper = FlankLoop(self, d, 0, 0, 0, 0, 0, runner=False)
        self.stepper.step()


def flank_contact_details(fc: FlankContacts, d: mujoco.MjData):
    """As wormsim.contact3d.sources.contact_details for flank contacts: (n teeth touching, max penetration, points in
    the frame of wheel tooth 0, forces on the wheel (world), points (world)). The kernel's contacts are d.contact's
    last fc.n entries; the force on the wheel (geom 2) is the elliptic-cone rows turned into the world frame
    (contact_sums.contact_forces, compiled: this runs at every sample)."""
    n = fc.n if fc.merge else min(fc.n, d.ncon)
    if n == 0:
        z = np.zeros((0, 3))
        return 0, 0.0, z, z, z
    adr_all, efc, frame, pos, cone3 = fc.slice_rows(d)
    out = np.empty((3, n, 3))
    th2 = float(d.qpos[fc.qa2])
    m, nteeth = contact_forces(adr_all, frame, pos, efc, cone3, fc.meta, th2, fc.bm.geometry.z2, out, fc.params)
    return nteeth, float(fc.depth[:n].max()), out[0, :m], out[1, :m], out[2, :m]
