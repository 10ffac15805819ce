"""Bulk hand-off of the exact-flank contacts to MuJoCo (wormsim.contact3d.flank_step): all of a step's contacts are
written and added from compiled code, one Python call per step.

Each contact is laid out in a buffer of mjContact records that this module owns: every record starts as a copy of
the template contact (as MuJoCo's mj_addContact stores it, so geoms, dim, friction, solimp and the rest are MuJoCo's
own bytes), the per-contact fields (dist, pos, frame, solref, solreffriction) are written into it by `fill_add`, which
then calls MuJoCo's C function mj_addContact (mujoco.h: "Add contact to d->contact list; return 0 if success;
1 if buffer full") on each record: MuJoCo copies it into d.contact exactly as the Python binding would. Field
offsets and the record size come from the binding's own views of d.contact (the struct is mjdata.h's mjContact, whose
first field is dist), so no layout is written here. The C function is called by address (wormsim.contact3d.native).
`fill_add`'s arguments are two records built once per model: `Handoff` (the buffer, its field offsets and the
contact law's solref) and `Handed` (the kernel's arrays of what is handed over).

Cost (docs/contact3d.md, "Exact flanks: cost"): the Python loop of mj_addContact and the per-field numpy writes
cost about 3 us per contact; here the C call is about 0.2 us per contact.
"""

from __future__ import annotations

import ctypes
from typing import NamedTuple

import mujoco
import numba
import numpy as np

from wormsim.contact3d.native import call_add

FIELDS = ("pos", "frame", "solref", "solreffriction", "friction")  # per-contact fields written besides dist


class Handoff(NamedTuple):
    """The record buffer of one model (ContactBuffer) and the contact law's solref (wormsim.contact3d.law)."""

    records: np.ndarray  # the buffer as float64 rows
    base: int  # its address
    size: int  # bytes per record
    offsets: np.ndarray  # of dist, pos, frame, solref, solreffriction, friction in float64 units
    solref: np.ndarray
    solreffriction: np.ndarray


class Handed(NamedTuple):
    """The contacts handed over, the kernel's arrays (wormsim.contact3d.flank_step.FlankContacts.handed)."""

    depth: np.ndarray
    pos: np.ndarray
    frame: np.ndarray
    weight: np.ndarray  # each contact's share of its slice
    fscale: np.ndarray  # the merged contacts' friction scale (wormsim.tooth.merge: mfric)


@numba.njit(cache=True)
def fill_add(fn, m_addr, d_addr, hand, n, out, mu, friction_rows, scale_friction):
    """Writes the per-contact fields of records 0..n-1 of hand (Handoff) from out (Handed): dist = -depth, solref
    (and, where friction_rows, solreffriction) scaled by the contact's share of its slice (direct solref: -k, -b);
    where scale_friction (one contact per tooth flank, wormsim.tooth.merge), the sliding friction mu fscale[i] and
    solreffriction scaled by weight fscale; then mj_addContact (at address fn) on each. Returns how many were added
    (it stops when the arena is full, where MuJoCo has warned with mjWARN_CONTACTFULL)."""
    rec, off, solref, solreffriction = hand.records, hand.offsets, hand.solref, hand.solreffriction
    depth, pos, frame, weight, fscale = out.depth, out.pos, out.frame, out.weight, out.fscale
    o0, o1, o2, o3, o4, o5 = off[0], off[1], off[2], off[3], off[4], off[5]
    for i in range(n):
        r = rec[i]
        r[o0] = -depth[i]
        for a in range(3):
            r[o1 + a] = pos[i, a]
        for a in range(9):
            r[o2 + a] = frame[i, a]
        w = weight[i]
        r[o3], r[o3 + 1] = w * solref[0], w * solref[1]
        wf = w * fscale[i] if scale_friction else w
        if friction_rows:
            r[o4], r[o4 + 1] = wf * solreffriction[0], wf * solreffriction[1]
        if scale_friction:
            r[o5] = r[o5 + 1] = mu * fscale[i]
    base, size = hand.base, hand.size
    for i in range(n):
        if call_add(fn, m_addr, d_addr, base + i * size) != 0:
            return i
    return n


class ContactBuffer:
    """mjContact records for up to `cap` contacts of one model, all copies of a template (module docstring)."""

    def __init__(self, m: mujoco.MjModel, template: mujoco.MjContact, cap: int):
        self.m = m
        self.cap = cap
        self._scratch = None
        self.bytes = None
        self.set_template(template)

    def set_template(self, template: mujoco.MjContact) -> None:
        """Refill every record from the template (as mj_addContact stores it) and read the field offsets."""
        d = self._scratch
        if d is None or mujoco.mj_addContact(self.m, d, template):  # appended to a scratch MjData (new when full)
            self._scratch = d = mujoco.MjData(self.m)
            if mujoco.mj_addContact(self.m, d, template):
                raise RuntimeError("mj_addContact: no room for one contact in a fresh MjData")
        c = d.contact
        dist = np.asarray(c.dist)
        size = dist.strides[0]
        base = dist.ctypes.data + (d.ncon - 1) * size
        raw = np.frombuffer((ctypes.c_char * size).from_address(base), dtype=np.uint8)
        if self.bytes is None:
            self.size = size
            self.bytes = np.ascontiguousarray(np.tile(raw, (self.cap, 1)))
            self.rec = self.bytes.view(np.float64)
            self.address = self.bytes.ctypes.data  # refilled in place below, so it stays
            off = [0] + [np.asarray(getattr(c, f)).ctypes.data - dist.ctypes.data for f in FIELDS]
            if any(o % 8 for o in off):
                raise RuntimeError(f"mjContact field offsets not float64-aligned: {off}")
            self.off = np.array(off, dtype=np.int64) // 8
        else:
            self.bytes[:] = raw

    def handoff(self, solref: np.ndarray, solreffriction: np.ndarray) -> Handoff:
        """fill_add's record of this buffer with the contact law's solref."""
        return Handoff(self.rec, int(self.address), int(self.size), self.off, solref, solreffriction)
