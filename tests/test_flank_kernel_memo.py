"""The exact-flank kernel's open-slice memo (wormsim.tooth.kernel.find_contacts, memo = flank_memo): the contacts
with the memo are the contacts without it, bit for bit, over a mesh cycle of states in sequence: the wheel loaded
with a varying transmission error, at mid-backlash, and jumping between the two (docs/contact3d.md, "Exact flanks:
cost")."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import SCENARIOS

from meshgen.geometry import derive
from wormsim.scenario import load_scenario
from wormsim.tooth import grid, kernel
from wormsim.tooth.window import window_size, window_teeth_at


def _states(g, steps: int) -> np.ndarray:
    """(theta1, theta2) over one mesh cycle: the wheel turned from the conjugate angle by s backlash angles j / (2 r2),
    s = 1.3 +- 0.2 (flank A loaded, the TE varying), then 0 (mid-backlash, open), then jumps between them."""
    bl = g.backlash / (2 * g.r2)
    th1 = np.linspace(0.3, 0.3 + 2 * math.pi / g.z1, steps)
    t = np.arange(steps)
    s = np.where(t < steps // 2, 1.3 + 0.2 * np.sin(2 * math.pi * 5 * t / steps), 0.0)
    s = np.where((t > 3 * steps // 4) & (t % 40 < 20), 1.5, s)  # closing at once from open
    return np.stack([th1, g.hand * th1 * g.z1 / g.z2 + g.hand * s * bl], axis=1)


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor"])
def test_memo_gives_the_same_contacts(name):
    """find_contacts with and without its memo, and find_packed (memo, slice_weights and frames in one call on
    PackedKernel's buffers) against find_contacts without memo + slice_weights + contact_frames."""
    g = derive(load_scenario(SCENARIOS / f"{name}.yaml").gear)
    S = 16
    fg = grid.flank_grid(g, S)
    W = window_size(g)
    tooth0 = -math.pi / 2 + math.pi / g.z2
    pitch = 2 * math.pi / g.z2
    margin = kernel.MARGIN_PITCH * pitch + g.backlash / (2 * g.r2)
    cap = 2 * W * S
    memo = kernel.flank_memo(fg, g.z2)
    pk = kernel.PackedKernel(fg, fg.params, cap, W, g.z2)
    runs: dict = {"memo": [], "none": [], "packed": []}
    for use in ("memo", "none"):
        bufs = [np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros((cap, 4)), np.zeros((cap, 2))]
        wf = [np.zeros(cap), np.zeros((cap, 9))]
        for th1, th2 in _states(g, 600):
            ks = window_teeth_at(th2, g.z2, W, tooth0).astype(np.int64)
            args = (fg.xy, fg.c, fg.c_range, fg.span, fg.zeta, ks, th1, th2, margin, fg.params, *bufs, 0.0)
            n = kernel.find_contacts(*args, memo if use == "memo" else None)
            runs[use].append([b[:n].copy() for b in bufs])
            if use == "none":
                pos, nrm, dep, meta, line = bufs
                n = kernel.slice_weights(meta, line, n, S, pos, nrm, dep, wf[0])
                kernel.contact_frames(nrm, n, wf[1])
                runs["weights"] = runs.get("weights", []) + [[b[:n].copy() for b in bufs + wf]]
                pk.ks[:] = ks
                m = kernel.find_packed(pk.fb, pk.ib, th1, th2, margin, 0.0)
                runs["packed"].append([b[:m].copy() for b in (pk.pos, pk.nrm, pk.depth, pk.meta, pk.line)])
                runs["packed"][-1] += [pk.weight[:m].copy(), pk.frame[:m].copy()]
    loaded = sum(len(a[2]) > 0 for a in runs["none"])
    assert loaded > 250  # the loaded half and the jumps touch
    for x, y in ((runs["memo"], runs["none"]), (runs["packed"], runs["weights"])):
        for a, b in zip(x, y):
            assert len(a[2]) == len(b[2])
            for u, v in zip(a, b):
                assert np.array_equal(u, v)
    # the memo was used: open slices remembered at the end of the sequence (mid-backlash stretch and jumps)
    for table in (memo[0], pk.memo):
        assert np.count_nonzero(table[..., 0] > 0) > 10
