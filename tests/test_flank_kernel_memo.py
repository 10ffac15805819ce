"""The exact-flank kernel's open-slice memo (wormsim.contact3d.flanks.find_contacts, memo = flank_memo): the contacts
with the memo are the contacts without it, bit for bit, over a mesh cycle of states in sequence: the wheel loaded
with a varying transmission error, at mid-backlash, and jumping between the two (docs/contact3d.md, "Exact flanks:
cost")."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import SCENARIOS

from meshgen.geometry import derive
from wormsim.contact3d import flanks as F
from wormsim.contact3d.window import window_size, window_teeth_at
from wormsim.scenario import load_scenario


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
    g = derive(load_scenario(SCENARIOS / f"{name}.yaml").gear)
    S = 16
    fg = F.flank_grid(g, S)
    W = window_size(g)
    tooth0 = -math.pi / 2 + math.pi / g.z2
    pitch = 2 * math.pi / g.z2
    margin = F.MARGIN_PITCH * pitch + g.backlash / (2 * g.r2)
    cap = 2 * W * S
    memo = F.flank_memo(fg, g.z2)
    runs = []
    for use in (memo, None):
        bufs = [np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros((cap, 4)), np.zeros((cap, 2))]
        out = []
        for th1, th2 in _states(g, 600):
            ks = window_teeth_at(th2, g.z2, W, tooth0).astype(np.int64)
            n = F.find_contacts(
                fg.xy, fg.c, fg.c_range, fg.span, fg.zeta, ks, th1, th2, margin, fg.params, *bufs, 0.0, use
            )
            out.append([b[:n].copy() for b in bufs])
        runs.append(out)
    with_memo, without = runs
    loaded = sum(len(a[2]) > 0 for a in without)
    assert loaded > 250  # the loaded half and the jumps touch
    for a, b in zip(with_memo, without):
        assert len(a[2]) == len(b[2])
        for x, y in zip(a, b):
            assert np.array_equal(x, y)
    # the memo was used: open slices remembered at the end of the sequence (mid-backlash stretch and jumps)
    assert np.count_nonzero(memo[0][..., 0] > 0) > 10
