"""Hostile and odd input (issue 10): every case exits 2 with one short line per problem naming the field (or the
file) and what is allowed; never a traceback, exit 1, a hang or runaway memory."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import types
import typing
from pathlib import Path

import pytest
from pydantic import BaseModel

from tests.conftest import ROOT
from wormsim import cli
from wormsim.scenario import MAX_PROBLEMS, Scenario

SEAT = ROOT / "scenarios" / "seat_motor.yaml"
MOV = ROOT / "scenarios" / "mov_1.yaml"
WORMSIM = Path(sys.executable).with_name("wormsim")
# exit codes asserted: 0 ok, 2 invalid input, 3 simulation failed, 130 / 143 interrupted (docs/cli.md, INTERFACE.md)


def _limit_memory():  # 2 GiB of address space: the billion laughs used 8 GB before the fix
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


def wormsim(*args, timeout=120):
    """The installed console script under a memory limit and a timeout (a hang fails the test)."""
    env = dict(os.environ, WORMSIM_NO_PROGRESS="1")
    return subprocess.run(
        [str(WORMSIM), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        preexec_fn=_limit_memory,
        env=env,
    )


def assert_input_error(r, *needles, max_lines=1):
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    lines = r.stderr.strip().splitlines()
    assert 1 <= len(lines) <= max_lines, r.stderr[-2000:]
    assert lines[0].startswith("error: ") and "Traceback" not in r.stderr and "Warning" not in r.stderr
    for n in needles:
        assert n in r.stderr, (n, r.stderr)


def test_binary_file(tmp_path):
    f = tmp_path / "g.yaml"
    f.write_bytes(bytes(range(256)) * 16)
    assert_input_error(wormsim("check", f), "not a UTF-8 text file")


def test_deep_nesting(tmp_path):
    f = tmp_path / "deep.yaml"
    f.write_text("wedge: " + "[" * 70000 + "]" * 70000 + "\n")  # 140 kB: RecursionError before the fix
    assert_input_error(wormsim("check", f), "nested deeper than")


BILLION_LAUGHS = """a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]
b: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a]
c: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b]
d: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c]
e: &e [*d,*d,*d,*d,*d,*d,*d,*d,*d]
f: &f [*e,*e,*e,*e,*e,*e,*e,*e,*e]
g: &g [*f,*f,*f,*f,*f,*f,*f,*f,*f]
h: &h [*g,*g,*g,*g,*g,*g,*g,*g,*g]
i: &i [*h,*h,*h,*h,*h,*h,*h,*h,*h]
wedge: *i
"""


def test_billion_laughs_fails_fast_in_small_memory(tmp_path):
    f = tmp_path / "bl.yaml"
    f.write_text(BILLION_LAUGHS)
    assert len(BILLION_LAUGHS) < 400
    r = wormsim("check", f, timeout=60)
    assert_input_error(r, "aliases expanded", "allowed at most")
    assert len(r.stderr) < 500  # was 2 GB of stderr


def test_small_alias_use_is_fine(tmp_path, capsys):
    f = tmp_path / "ok.yaml"
    f.write_text(
        "name: alias\nmodel: wedge\nwedge:\n  driving_mass_kg: &m 11.8\n  driven_mass_kg: *m\n"
        "  load: &l {force_n: -100}\n"
    )
    assert cli.main(["check", str(f)]) == 0
    assert "driven_mass_kg: 11.8" in capsys.readouterr().out


def test_file_size_limit(tmp_path):
    f = tmp_path / "big.yaml"
    f.write_text("name: x\n" + "#" * 300_000 + "\n")
    assert_input_error(wormsim("check", f), "at most 256000 bytes")


def test_many_problems_are_capped(tmp_path):
    f = tmp_path / "keys.yaml"
    f.write_text("name: x\nmodel: wedge\nwedge: {}\n" + "".join(f"k{i}: 1\n" for i in range(20000)))
    r = wormsim("check", f)
    assert_input_error(r, "unknown key 'k0'", f"and {20000 - MAX_PROBLEMS} more problems", max_lines=MAX_PROBLEMS + 1)
    assert len(r.stderr) < 3000  # 700k unknown keys wrote 56 MB before the fix


def test_long_values_are_abbreviated(capsys):
    assert (
        cli.main(["check", str(SEAT), "--set", "name=" + "X" * 100_000, "--set", "gear.wheel_teeth=" + "9" * 5000]) == 2
    )
    err = capsys.readouterr().err
    assert len(err) < 600 and err.count("\n") <= 2, err[:1000]


def _float_fields(model: type[BaseModel], prefix: str = ""):
    for name, info in model.model_fields.items():
        ann = info.annotation
        args = (
            typing.get_args(ann)
            if isinstance(ann, types.UnionType) or typing.get_origin(ann) is typing.Union
            else (ann,)
        )
        for a in args:
            if a is float:
                yield prefix + name
            elif isinstance(a, type) and issubclass(a, BaseModel):
                yield from _float_fields(a, f"{prefix}{name}.")


FLOAT_FIELDS = sorted(set(_float_fields(Scenario)))


def test_float_fields_found():
    assert {
        "gear.worm_length_mm",
        "wedge.initial_speed_m_s",
        "wedge.driving_mass_kg",
        "drive.ramp_s",
        "load.ramp_s",
        "wedge.load.ramp_s",
    } <= set(FLOAT_FIELDS)
    assert len(FLOAT_FIELDS) > 40


@pytest.mark.parametrize("value", [".inf", "-.inf", ".nan"])
def test_every_float_field_refuses_non_finite(value, capsys):
    for path in FLOAT_FIELDS:
        base = MOV if path.startswith("wedge.") else SEAT
        code = cli.main(["check", str(base), "--set", f"{path}={value}"])
        err = capsys.readouterr().err
        assert code == 2, (path, err)
        assert path in err and "finite number" in err and "allowed" in err, (path, err)


@pytest.mark.parametrize(
    "setting, needle",
    [
        ("gear.worm_length_mm=.inf", "gear.worm_length_mm"),  # OverflowError, exit 1 before
        ("gear.worm_length_mm=1e6", "gear.worm_length_mm"),  # ran > 10 min at 5 GB before
        ("gear.worm_length_mm=500", "gear.worm_length_mm = 500: allowed"),  # 4 x the mesh zone
        ("gear.worm_length_mm=1", "gear.worm_length_mm = 1: allowed"),  # below one axial pitch
        ("gear.lead_angle_deg=1e-9", "gear.lead_angle_deg"),  # d1 = 4e10 mm before
        ("gear.face_width_mm=1000", "gear.face_width_mm"),
        ("gear.backlash_mm=5", "gear.backlash_mm"),  # check accepted it before
        ("gear.normal_pressure_angle_deg=5", "undercut"),  # meshgen's wheel check
        ("simulation.duration_s=1e9", "simulation.duration_s"),
    ],
)
@pytest.mark.parametrize("command", ["check", "mesh", "run"])
def test_size_bounds_same_in_check_mesh_run(setting, needle, command, tmp_path, capsys):
    out = ["--out", str(tmp_path / "o")] if command != "check" else []
    code = cli.main([command, str(SEAT), "--set", setting, *out])
    err = capsys.readouterr().err
    assert code == 2 and needle in err and ("allowed" in err or "raise" in err), err
    assert code == 2 and err.count("\n") == 1 and err.startswith("error: "), err


def test_no_numpy_warnings_before_the_error():
    r = wormsim("run", SEAT, "--out", "/dev/null/x", "--set", "gear.lead_angle_deg=44.9", "--set", "model=torsional")
    assert_input_error(r)
