"""Robustness (issue 10): random valid gear data either runs at torsional with the ratio within 0.1 % and the
torque balance within 2 %, or is refused with exit 2 -- never exit 1, never a hang; and a fuzz test of the scenario
loader with mutated seed files -- only a Scenario or exit 2, in bounded time and memory.

contact3d runs in a second property test with exact flanks (contact.geometry flanks, coarse: 8 slices), a few
seeded gears, short runs: the ratio within 0.1 % and F_t r2 within 2 % of the load, or exit 2. (With convex
pieces, meshing one new random gear set took about 55 s on the 2-core CI machine, beyond this test's budget.)"""

from __future__ import annotations

import json
import resource
import subprocess
import sys

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import ROOT, time_limit
from wormsim import cli

SEEDS = sorted((ROOT / "scenarios").glob("*.yaml")) + sorted((ROOT / "tests" / "assets").glob("*.yaml"))


gear_data = st.fixed_dictionaries(
    {
        "worm_starts": st.integers(1, 4),
        "wheel_teeth": st.integers(20, 80),
        "axial_module_mm": st.floats(0.5, 12),
        "diameter_quotient": st.floats(6, 16),
        "normal_pressure_angle_deg": st.floats(10, 25),
        "hand": st.sampled_from(["right", "left"]),
        "profile": st.sampled_from(["ZI", "ZA"]),
    }
)


OUTCOMES: list[int] = []


@settings(
    max_examples=8,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(gear=gear_data)
def test_random_gear_runs_or_is_refused(gear, tmp_path_factory, capsys):
    m = gear["axial_module_mm"]
    load_nm = 0.04 * m**3 * gear["wheel_teeth"]  # a tangential force of about 10 N/mm^2 x m x 8 m
    scenario = {
        "name": "prop",
        "model": "torsional",
        "gear": {**gear, "backlash_mm": 0.05 * m},
        "drive": {"speed_rpm": 600, "ramp_s": 0.05},
        "load": {"torque_nm": load_nm, "ramp_s": 0.05},
        "simulation": {"duration_s": 0.3},
    }
    d = tmp_path_factory.mktemp("prop")
    (d / "s.yaml").write_text(yaml.safe_dump(scenario))
    with time_limit(120):
        code = cli.main(["run", str(d / "s.yaml"), "--out", str(d / "o"), "--no-progress"])
    err = capsys.readouterr().err
    OUTCOMES.append(code)
    assert code in (0, 2), (gear, code, err)
    if code == 2:
        assert err.startswith("error: ") and err.count("\n") == 1 and "gear" in err, (gear, err)
        return
    s = json.loads((d / "o" / "summary.json").read_text())
    assert s["status"] == "ok"
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3, (gear, s["ratio"], s["ratio_theory"])
    # torque balance from the mesh force, not from the load command: the mean tangential force of the mesh spring
    # times r2 carries the load (statics of the wheel: its mean acceleration over the window is zero), within 2 %;
    # tangential_force_theory_n = T2 / r2 (DIN 3975-2, wormsim.physics.gear_theory.tangential_force_n)
    assert abs(s["tangential_force_mean_n"] / s["tangential_force_theory_n"] - 1) < 0.02, (
        gear,
        s["tangential_force_mean_n"],
        s["tangential_force_theory_n"],
    )


CONTACT3D_OUTCOMES: list[int] = []


def seeded_gears(n: int, seed: int) -> list[dict]:
    """n gears of gear_data's ranges from a seeded generator: the same gears in every process (hypothesis's
    derandomized examples differed between a file run alone and the suite under xdist)."""
    rng = np.random.default_rng(seed)
    return [
        {
            "worm_starts": int(rng.integers(1, 5)),
            "wheel_teeth": int(rng.integers(20, 81)),
            "axial_module_mm": float(rng.uniform(0.5, 12)),
            "diameter_quotient": float(rng.uniform(6, 16)),
            "normal_pressure_angle_deg": float(rng.uniform(10, 25)),
            "hand": str(rng.choice(["right", "left"])),
            "profile": str(rng.choice(["ZI", "ZA"])),
        }
        for _ in range(n)
    ]


@pytest.mark.parametrize("gear", seeded_gears(3, 31), ids=lambda g: f"{g['worm_starts']}x{g['wheel_teeth']}")
def test_random_gear_runs_at_contact3d_with_flanks_or_is_refused(gear, tmp_path_factory, capsys):
    """Any valid gear data must work at contact3d too (INTERFACE.md): exit 0 with the ratio and the torque balance,
    or exit 2 with one line. 3000 rpm, 5 ms ramps, 0.05 s (at least 2.5 mesh periods). Hertz's contact stiffness:
    the teeth's compliance costs an FE solve of 20-60 s per new gear here (these gears' contact, not its stiffness,
    is the point; tests/tooth/test_compliance.py covers random gears' compliance)."""
    m = gear["axial_module_mm"]
    load_nm = 0.04 * m**3 * gear["wheel_teeth"]
    scenario = {
        "name": "prop3d",
        "model": "contact3d",
        "gear": {**gear, "backlash_mm": 0.05 * m},
        "materials": {
            "worm": {"youngs_modulus_gpa": 210, "poisson_ratio": 0.3, "density_kg_m3": 7850},
            "wheel": {"youngs_modulus_gpa": 100, "poisson_ratio": 0.34, "density_kg_m3": 8800},
        },
        "contact": {"geometry": "flanks", "friction": 0.05, "stiffness_model": "hertz"},
        "drive": {"speed_rpm": 3000, "ramp_s": 0.005},
        "load": {"torque_nm": load_nm, "ramp_s": 0.005},
        "simulation": {"duration_s": 0.05, "resolution": "coarse"},
    }
    d = tmp_path_factory.mktemp("prop3d")
    (d / "s.yaml").write_text(yaml.safe_dump(scenario))
    with time_limit(120):
        code = cli.main(["run", str(d / "s.yaml"), "--out", str(d / "o"), "--no-progress"])
    err = capsys.readouterr().err
    CONTACT3D_OUTCOMES.append(code)
    assert code in (0, 2), (gear, code, err)
    if code == 2:
        assert err.startswith("error: ") and err.count("\n") == 1 and "gear" in err, (gear, err)
        return
    s = json.loads((d / "o" / "summary.json").read_text())
    assert s["status"] == "ok" and s["contact_geometry"] == "flanks"
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3, (gear, s["ratio"], s["ratio_theory"])
    assert abs(s["tangential_force_mean_n"] / s["tangential_force_theory_n"] - 1) < 0.02, (
        gear,
        s["tangential_force_mean_n"],
        s["tangential_force_theory_n"],
    )


def test_random_gears_mostly_run_at_contact3d():
    """Not vacuous: most seeded gears of the contact3d property test run (the test above, in this process)."""
    if len(CONTACT3D_OUTCOMES) < 3:
        pytest.skip("run with test_random_gear_runs_at_contact3d_with_flanks_or_is_refused")
    assert CONTACT3D_OUTCOMES.count(0) >= 2, CONTACT3D_OUTCOMES


def test_random_gears_mostly_run():
    """The property test above is not vacuous: most of its (derandomized) gears run (measured: 7 of 8, one undercut refused)."""
    if not OUTCOMES:
        pytest.skip("run with test_random_gear_runs_or_is_refused (in this process)")
    assert OUTCOMES.count(0) >= len(OUTCOMES) // 2, OUTCOMES


# ----------------------------------------------------------------------------- fuzz of the loader

FUZZ_WORKER = r"""
import json, random, sys, traceback
from pathlib import Path
from wormsim.scenario import ScenarioError, load_scenario
from wormsim.physics.validate import validate_geometry

seeds, n, tmp = [Path(p) for p in json.loads(sys.argv[1])], int(sys.argv[2]), Path(sys.argv[3])
rng = random.Random(20251123)
TOKENS = [b"&a ", b"*a", b"[", b"]", b"{", b"}", b": ", b"- ", b"!!binary ", b"!!python/object:os.system ",
          b".inf", b"-.nan", b"1e999", b"9" * 5000, b"\x00", b"\xff\xfe", b"'", b'"', b"\t", b"? ", b"|\n",
          b"<<: *a\n", b"~", b"null", b"-1e-300", b"0x7fffffffffffffff", b"2001-12-14", b"\n" * 3, b"#"]
bad = []
for i in range(n):
    src = rng.choice(seeds).read_bytes()
    data = bytearray(src)
    for _ in range(rng.randint(1, 6)):
        op, pos = rng.random(), rng.randrange(len(data) + 1)
        if op < 0.3:
            data[pos:pos] = rng.choice(TOKENS)
        elif op < 0.5:
            del data[pos:pos + rng.randint(1, 40)]
        elif op < 0.7 and len(data):
            data[pos % len(data)] = rng.randrange(256)
        elif op < 0.85:
            lines = data.split(b"\n")
            k = rng.randrange(len(lines))
            lines.insert(k, lines[rng.randrange(len(lines))])
            data = bytearray(b"\n".join(lines))
        else:
            data = data.replace(b"0.", rng.choice([b"-0.", b"1e308", b".inf", b"0x"]), 1)
    f = tmp / f"m{i}.yaml"
    f.write_bytes(bytes(data))
    try:
        validate_geometry(load_scenario(f))
    except ScenarioError as exc:
        msg = str(exc)
        if len(msg) > 4000 or not msg.strip():
            bad.append([i, "message", msg[:300]])
    except BaseException as exc:
        bad.append([i, type(exc).__name__, traceback.format_exc()[-600:]])
print(json.dumps(bad))
"""


def _limits():
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


def test_fuzz_scenario_loader(tmp_path):
    r = subprocess.run(
        [sys.executable, "-c", FUZZ_WORKER, json.dumps([str(p) for p in SEEDS]), "400", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=_limits,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    bad = json.loads(r.stdout.strip().splitlines()[-1])
    assert bad == [], bad[:5]
