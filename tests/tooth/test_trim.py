"""The flank grid's trim (wormsim.tooth.trim): a generated flank point is not cut by the conjugate worm; the same
point moved 20 um into the tooth space (into the thread) is cut, moved 20 um into the tooth it is not."""

from __future__ import annotations

import math

import numpy as np

from meshgen import wheel
from tests.conftest import SCENARIOS
from wormsim.physics.geometry import derive
from wormsim.scenario import load_scenario
from wormsim.tooth.grid import worm_params
from wormsim.tooth.trim import cut_points
from wormsim.tooth.window import window_size


def test_generated_points_stay_and_points_inside_the_thread_are_cut():
    g = derive(load_scenario(SCENARIOS / "screw_jack.yaml").gear)
    zeta = np.array([0.0])
    P, window = worm_params(g), float(window_size(g))
    for side in (+1, -1):
        R = np.linspace(g.r2 - 0.8 * g.m_x, g.r2 + 0.8 * g.m_x, 9)[None, :]
        sol = wheel.space_flank(g, R, np.zeros_like(R), side)
        ok = sol.interior[0]
        assert ok.sum() >= 6  # the envelope's points on the flank (not past the root or the tip)
        R, psi0 = R[:, ok], sol.psi[:, ok]

        def cut(dpsi):
            psi = psi0 + dpsi / R
            xy = np.stack([R * np.cos(psi), R * np.sin(psi)], axis=-1)[None]
            return cut_points(xy, zeta, P, window)[0]

        assert not cut(0.0).any()
        moved = {s: cut(s * 20e-6) for s in (+1, -1)}
        # one direction is into the thread (every point cut), the other into the tooth (none)
        assert sorted(m.all() for m in moved.values()) == [False, True]
        assert sorted(m.any() for m in moved.values()) == [False, True]
    assert math.isfinite(window) and window > 1
