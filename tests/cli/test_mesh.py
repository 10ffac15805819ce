"""`wormsim mesh SCENARIO --out DIR`: files, frames in assembly.json, recording, input errors (exit 2)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import trimesh

from meshgen import assembly
from tests._meshgen_common import ROOT
from wormsim.cli import main


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("WORMSIM_CACHE", str(tmp_path / "cache"))


@pytest.mark.parametrize("name", ["seat_motor", "involute_41"])
def test_mesh_command_writes_geometry(name, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["mesh", str(ROOT / "scenarios" / f"{name}.yaml"), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "a_mm" in text and "gamma_b_deg" in text and "recording.rrd" in text
    data = json.loads((out / "assembly.json").read_text())
    a = data["center_distance_m"]
    assert a == pytest.approx(data["derived"]["a_mm"] / 1000)
    Tw, Tg = np.array(data["worm"]["transform"]), np.array(data["wheel"]["transform"])
    # worm axis parallel to x at y = -a, z = 0; wheel frame = assembly frame at angle 0
    assert np.allclose(Tw[:3, 3], [0, -a, 0]) and np.allclose(np.abs(Tw[:3, 2]), [1, 0, 0])
    assert np.allclose(Tg, np.eye(4))
    worm = trimesh.load(out / "worm.stl")
    wheel = trimesh.load(out / "wheel.stl")
    assert worm.is_watertight and wheel.is_watertight and worm.volume > 0 and wheel.volume > 0
    assert worm.volume == pytest.approx(data["worm"]["volume_m3"], rel=1e-6)
    # the meshes, placed by the transforms, do not overlap at angle 0 and sit a centre distance apart
    ww = worm.copy().apply_transform(Tw)
    assert ww.bounds[0][1] == pytest.approx(-a - worm.bounds[1][0], rel=1e-3)
    assert wheel.bounds[1][0] == pytest.approx(data["derived"]["r_e2_mm"] / 1000, rel=1e-3)
    from wormsim.results.recording import recorded_entities

    ents = recorded_entities(out / "recording.rrd")
    assert {"/assembly/worm", "/assembly/wheel"} <= ents
    assert data["piece_error_um"]["worm"]["max"] >= 0
    # section.png: a PNG file (its 8-byte signature, PNG spec 5.2) of a real picture, not an empty canvas
    png = (out / "section.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    assert not list(out.glob(".*.png"))  # the temporary name was renamed


def test_assembly_transforms_consistent():
    """worm_to_assembly(theta1) turns about the worm axis (assembly -x) and keeps the axis at y = -a."""
    T0, T1 = assembly.worm_to_assembly(0.0, 0.1), assembly.worm_to_assembly(0.3, 0.1)
    axis = T0[:3, 2]
    assert np.allclose(axis, [-1, 0, 0]) and np.allclose(T1[:3, 2], axis)
    rel = np.linalg.inv(T0) @ T1
    assert rel[0, 0] == pytest.approx(math.cos(0.3)) and rel[1, 0] == pytest.approx(math.sin(0.3))
    assert np.allclose(assembly.wheel_to_assembly(0.2)[:3, :3] @ [1, 0, 0], [math.cos(0.2), math.sin(0.2), 0])


@pytest.mark.parametrize(
    "override,field",
    [
        ("gear.normal_pressure_angle_deg=6", "gear.normal_pressure_angle_deg"),
        ("gear.backlash_mm=20", "gear.backlash_mm"),
    ],
)
def test_mesh_command_input_error_exit_2(override, field, tmp_path, capsys):
    code = main(
        [
            "mesh",
            str(ROOT / "scenarios" / "involute_41.yaml"),
            "--out",
            str(tmp_path / "o"),
            "--set",
            override,
            "--set",
            "gear.wheel_teeth=20",
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert field in err
    assert not (tmp_path / "o" / "wheel.stl").exists()
