"""Stepping a built contact3d model in a test as wormsim.contact3d.runner steps it, for either contact.geometry:
pieces (mj_step, the window of wheel-tooth pieces re-posed, mu on the collision geoms) or flanks (the split step
with the contacts found on the exact flanks, wormsim.contact3d.flank_step; mu on their template)."""

from __future__ import annotations

import mujoco
import numpy as np

from wormsim.contact3d.slots import repose_window


class Stepper:
    def __init__(self, bm, d: mujoco.MjData):
        self.bm, self.m, self.d = bm, bm.model, d
        self.flanks = bm.plan.flanks
        m = self.m
        self.qa_wheel = int(m.jnt_qposadr[m.dof_jntid[bm.wheel_dof]])
        if self.flanks:
            from wormsim.contact3d.flank_step import FlankContacts
            from wormsim.contact3d.native import split_forward

            self.fc = FlankContacts(bm, bm.law.contacts_per_pair)
            split_forward(m, d, self.fc.add)
        else:
            self.fc = None
            self.coll = np.concatenate([bm.worm_geoms, bm.wheel_slot_geoms.ravel()])
            self.window = repose_window(bm, float(d.qpos[self.qa_wheel]))
            mujoco.mj_forward(m, d)

    def step(self, n: int = 1) -> None:
        """n steps; pieces: the window re-posed after them (the runner does so every record interval)."""
        if self.fc is not None:
            for _ in range(n):
                self.fc.step(self.m, self.d)
        else:
            mujoco.mj_step(self.m, self.d, nstep=n)
            self.window = repose_window(self.bm, float(self.d.qpos[self.qa_wheel]), self.window)

    def set_friction(self, mu: float) -> None:
        if self.fc is not None:
            self.fc.set_friction(mu)
        else:
            self.m.geom_friction[self.coll, 0] = mu
