"""The stick state's break-away (wormsim.contact3d.breakaway): the share of the contacts' static friction that holding
the worm on its hinge needs, by hand on given rows, and on a held pair against the pitch-point self-locking ratio."""

from __future__ import annotations

import math

import numpy as np
import pytest

import wormsim.contact3d.flank_samples as FS
import wormsim.contact3d.runner as R
from meshgen.geometry import derive
from tests.conftest import SCENARIOS as SCEN
from wormsim.contact3d.breakaway import hinge_utilisation, static_utilisation
from wormsim.contact3d.runner import simulate
from wormsim.scenario import load_scenario

DEMO = SCEN / "seat_motor_demo.yaml"


def test_hinge_utilisation_by_hand():
    """Two elliptic-cone contacts (rows at 0 and 3) and a frictionless one (dim 1, row 6, left out): need =
    |sum J_n f_n + qfrc_smooth|, limit = sum mu f_n |J_t|."""
    adr = np.array([0, 3, 6])
    dim = np.array([3, 3, 1])
    mu = np.array([0.1, 0.2, 0.5])
    f = np.array([10.0, 1.0, -2.0, 20.0, 0.5, 0.5, 7.0])
    col = np.array([0.02, 0.003, 0.004, -0.01, 0.0, 0.006, 1.0])
    need = 0.02 * 10.0 - 0.01 * 20.0 + 0.05
    limit = 0.1 * 10.0 * 0.005 + 0.2 * 20.0 * 0.006
    assert hinge_utilisation(adr, dim, mu, 3, f, col, 0.05) == pytest.approx(abs(need) / limit, rel=1e-12)
    assert hinge_utilisation(adr, dim, mu, 0, f, col, 0.05) == 0.0  # no contact: nothing to hold with


def test_held_pair_needs_the_pitch_point_share_of_its_static_friction(monkeypatch):
    """The seat motor demo gear (coarse), 2 N m on the wheel in 2 ms, the worm free, mu_s 0.3 deg above and mu_d 0.3
    deg below the locking boundary, 5 ms: the held pair needs the same share of its static friction through the ramp
    and after it, below 1 and near the pitch point's tan(gamma) / tan(rho'_s) (0.941): measured 0.910-0.911 (contact3d's
    contacts off the pitch point lock with 3.4 % less friction, tests/contact3d/test_backlash.py)."""
    g = derive(load_scenario(DEMO).gear)
    mu_s, mu_d = (math.cos(g.alpha_n) * math.tan(g.gamma + math.radians(x)) for x in (0.3, -0.3))
    seen: list[tuple[float, float]] = []

    def recorded(m, d, dof):
        u = static_utilisation(m, d, dof)
        seen.append((float(d.time), u))
        return u

    monkeypatch.setattr(FS, "ENABLED", False)  # the Python samples, where the runner calls static_utilisation
    monkeypatch.setattr(R, "static_utilisation", recorded)
    sets = ["drive.on=wheel", "drive.speed_rpm=null", "drive.torque_nm=2.0", "drive.ramp_s=0.002", "load.on=worm"]
    sets += ["load.torque_nm=0", "load.ramp_s=0", "simulation.resolution=coarse", "simulation.duration_s=0.005"]
    sets += ["contact.friction=null", f"contact.friction_static={mu_s!r}", f"contact.friction_dynamic={mu_d!r}"]
    res = simulate(load_scenario(DEMO, sets))
    assert res.summary["locked"] is True
    t, u = np.array(seen).T
    loaded = u[t > 0.0005]
    hand = math.tan(g.gamma) / math.tan(math.atan(mu_s / math.cos(g.alpha_n)))
    assert loaded.max() < 1.0 and np.ptp(loaded) < 0.01, (loaded.min(), loaded.max())
    assert abs(loaded[-1] / hand - 1) < 0.06, (loaded[-1], hand)
