"""What a new user sees first (issue 10): `wormsim mesh`'s printout and a model.xml that moves in the viewer."""

from __future__ import annotations

import math

import mujoco
import pytest

from tests.conftest import ROOT
from wormsim import cli

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"


def test_mesh_prints_words_not_codes(tmp_path, capsys):
    assert cli.main(["mesh", str(MINIMAL), "--out", str(tmp_path / "m")]) == 0
    out = capsys.readouterr().out
    assert "hand" in out and "right" in out.split("hand", 1)[1].splitlines()[0]
    assert "Resolution(" not in out and "resolution medium: 48 worm segments per turn" in out


def test_model_xml_actuators_follow_their_controls(tmp_path):
    """`wormsim model`'s MJCF (docs/mjcf.md): the keyframe `scenario` holds the scenario's commands as controls
    (minimal_contact3d.yaml: the worm at 600 rpm, 5 N m resisting on the wheel); from it the worm turns at 600 rpm
    and drives the wheel (30 teeth, 1 start); the drive's control is the worm speed in rpm (300 -> 300 rpm) and the
    load's the wheel torque in N m (doubling it doubles the torque the drive delivers: T1 = T2 / (i eta), DIN 3975)."""
    import numpy as np

    assert cli.main(["model", str(MINIMAL), "--out", str(tmp_path / "m")]) == 0
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "m" / "model.xml"))
    d = mujoco.MjData(m)
    drive, load = m.actuator("drive").id, m.actuator("load").id
    assert not m.actuator_biasprm[:, 0].any()  # no constant bias term: the controls are the commands
    mujoco.mj_resetDataKeyframe(m, d, m.key("scenario").id)
    # the keyframe's controls: drive.speed_rpm 600, load.torque_nm 5 resisting (tests/assets/minimal_contact3d.yaml)
    assert d.ctrl[drive] == pytest.approx(600.0) and d.ctrl[load] == pytest.approx(-5.0)
    worm = m.joint("worm_hinge").dofadr[0]
    wheel = m.joint("wheel_hinge").dofadr[0]

    def run(duration_s):
        """Step; the drive's mean torque on the worm over the last 2.5 ms."""
        n = int(duration_s / m.opt.timestep)
        tail = []
        for i in range(n):
            mujoco.mj_step(m, d)
            if i >= n - int(2.5e-3 / m.opt.timestep):
                tail.append(d.qfrc_actuator[worm])
        return float(np.mean(tail))

    run(0.03)
    rpm = 30 / math.pi
    assert d.qvel[worm] * rpm == pytest.approx(600.0, rel=0.02)
    assert d.qvel[wheel] * rpm == pytest.approx(600.0 / 30, rel=0.1)
    d.ctrl[drive] = 300.0
    t1 = run(0.02)
    assert d.qvel[worm] * rpm == pytest.approx(300.0, rel=0.02)
    d.ctrl[load] = -10.0
    t1_double = run(0.015)
    # the load control of -10 N m set above (echoed back by the motor actuator)
    assert d.qfrc_actuator[wheel] == pytest.approx(-10.0)
    assert t1_double / t1 == pytest.approx(2.0, rel=0.15)
