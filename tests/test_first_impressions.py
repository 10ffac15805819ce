"""What a new user sees first (issue 10): `wormsim mesh`'s printout and a model.xml that moves in the viewer."""

from __future__ import annotations

import math

import mujoco
import pytest
from conftest import ROOT

from wormsim import cli

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"


def test_mesh_prints_words_not_codes(tmp_path, capsys):
    assert cli.main(["mesh", str(MINIMAL), "--out", str(tmp_path / "m")]) == 0
    out = capsys.readouterr().out
    assert "hand" in out and "right" in out.split("hand", 1)[1].splitlines()[0]
    assert "Resolution(" not in out and "resolution medium: 48 worm segments per turn" in out


def test_model_xml_turns_the_worm_with_zero_controls(tmp_path):
    assert cli.main(["model", str(MINIMAL), "--out", str(tmp_path / "m")]) == 0
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "m" / "model.xml"))
    d = mujoco.MjData(m)
    assert not d.ctrl.any()
    for _ in range(int(0.03 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    worm = m.joint("worm_hinge").dofadr[0]
    wheel = m.joint("wheel_hinge").dofadr[0]
    w_cmd = 600 * 2 * math.pi / 60  # minimal_contact3d.yaml: drive.speed_rpm 600 on the worm
    assert abs(d.qvel[worm]) == pytest.approx(w_cmd, rel=0.02)
    assert abs(d.qvel[wheel]) == pytest.approx(w_cmd / 30, rel=0.1)  # 30 teeth, 1 start: the wheel is driven
