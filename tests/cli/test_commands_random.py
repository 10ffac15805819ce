"""No exit 1 from any command on a valid gear (issue 31): random valid gear data run through every command as a user
runs it -- `wormsim init`, the template edited, then check, run at wedge / torsional / contact3d (short), run
--rexs (REXS export), import of that file and check of the imported scenario, rate, rate --fe, mesh, model and a
2-point sweep -- each through the console script's main (wormsim.cli.main, its exit code and its stderr).

Each command exits 0, 2 (bad input: the last line of stderr is `error: ...` naming the field) or 3 (a refusal:
`simulation failed: ...`), never 1 (an internal error) and never with a traceback. A sweep's failed point carries
its message in sweep.csv / sweep.json, and none is an internal error.

The gears: numpy's default_rng([SEED, index]) over the schema's ranges (docs/scenario.md), in the region a drive
engineer uses: every profile (ZA, ZN, ZI, ZK, ZC), either hand, z1 1-8, z2 10-200 (mostly 20-80), m_x 0.3-16 mm
(log-uniform), q 6-18, alpha_n 8-28 deg, x2 -0.6 to 0.6 or none, face width none or 0.4-1.15 worm tip diameters,
the wheel of bronze, aluminium bronze, nodular or grey cast iron or POM, 100-3000 rpm, and a load around
0.04 m_x^3 z2 N m (a tenth of it for POM) times 0.2-2. The scenario file sets contact.stiffness_model=hertz (the
teeth's FE compliance of each new gear costs 10-30 s at torsional and contact3d), except for every tenth gear of the
long test, which keeps the default (the teeth's FE compliance: a mesh gmsh refuses is retried, else exit 3).

`make test` runs CI_GEARS (three gears, each command on at least one of them; about 35 s of CPU); the long test
(tests/conftest.py LONG_TESTS) runs LONG_GEARS gears with every command (about 70 min on 2 busy cores with
`-n 2`). WORMSIM_COMMANDS_LOG=FILE appends one JSON line per gear (exit codes, wall times, refusal messages)."""

from __future__ import annotations

import json
import math
import os
import re
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import time_limit
from wormsim import cli
from wormsim.scenario import yaml_load

SEED = 3131
LONG_GEARS = 100
TEETH_EVERY = 10  # every tenth gear of the long test runs contact3d with the default stiffness (the FE compliance)

# wheel materials: the scenario's materials.wheel and the rating's wheel_material (wormsim.rating.materials)
WHEELS = {
    "CuSn12Ni2": {"youngs_modulus_gpa": 98.1, "poisson_ratio": 0.35, "density_kg_m3": 8800},
    "CuAl10Fe5Ni5": {"youngs_modulus_gpa": 122.6, "poisson_ratio": 0.35, "density_kg_m3": 7600},
    "GJS-400": {"youngs_modulus_gpa": 175, "poisson_ratio": 0.3, "density_kg_m3": 7100},
    "GJL-250": {"youngs_modulus_gpa": 98.1, "poisson_ratio": 0.3, "density_kg_m3": 7200},
    "POM": {"youngs_modulus_gpa": 3.0, "poisson_ratio": 0.35, "density_kg_m3": 1410},
}
STEEL = {"youngs_modulus_gpa": 210, "poisson_ratio": 0.3, "density_kg_m3": 7850}


def draw(index: int) -> dict:
    """Gear data, materials, speed and load of random gear `index`: the blocks to write into init's template."""
    rng = np.random.default_rng([SEED, index])
    m = float(np.exp(rng.uniform(math.log(0.3), math.log(16))))
    z1 = int(rng.choice(np.arange(1, 9), p=[0.3, 0.25, 0.15, 0.12, 0.06, 0.06, 0.03, 0.03]))
    z2 = int(rng.integers(20, 81)) if rng.random() < 0.8 else int(rng.integers(10, 201))
    q = float(rng.uniform(6, 18))
    gear = {
        "profile": str(rng.choice(["ZA", "ZN", "ZI", "ZK", "ZC"])),
        "hand": str(rng.choice(["right", "left"])),
        "worm_starts": z1,
        "wheel_teeth": z2,
        "axial_module_mm": round(m, 3),
        "diameter_quotient": round(q, 2),
        "normal_pressure_angle_deg": round(float(rng.uniform(8, 28)), 1),
        "face_width_mm": None,
        "backlash_mm": round(0.05 * m, 4),
    }
    if rng.random() < 0.5:
        gear["profile_shift_coefficient"] = round(float(rng.uniform(-0.6, 0.6)), 2)
    if rng.random() < 0.5:
        tip_mm = (q + 2) * m
        gear["face_width_mm"] = round(max(m, float(rng.uniform(0.4, 1.15)) * tip_mm), 2)
    wheel = str(rng.choice(list(WHEELS)))
    load_nm = (
        0.04 * m**3 * z2 * (0.1 if wheel == "POM" else 1.0) * float(np.exp(rng.uniform(math.log(0.2), math.log(2))))
    )
    return {
        "gear": gear,
        "materials": {"worm": STEEL, "wheel": WHEELS[wheel]},
        "rating": {"wheel_material": wheel},
        "speed_rpm": round(float(np.exp(rng.uniform(math.log(100), math.log(3000)))), 1),
        "load_nm": round(load_nm, 4),
    }


FIELD = re.compile(r"\b[a-z_]+\.[a-z_0-9]+\b|\bgear\b|--[a-z]+")


class User:
    """Runs commands as `wormsim ...` would (cli.main) in one folder and checks each exit: 0, 2 or 3, never 1."""

    def __init__(self, folder: Path, capfd, label: str):
        self.dir, self.capfd, self.label = folder, capfd, label
        self.codes: dict[str, int] = {}
        self.wall_s: dict[str, float] = {}
        self.messages: dict[str, str] = {}  # the last stderr line of each command that exits 2 or 3

    def __call__(self, name: str, *argv: str, limit_s: int = 300) -> int:
        self.capfd.readouterr()
        t0 = time.perf_counter()
        with time_limit(limit_s):
            try:
                code = cli.main(list(argv))
            except SystemExit as exc:  # argparse: a bad command line
                code = exc.code if isinstance(exc.code, int) else 1
        self.wall_s[name] = round(time.perf_counter() - t0, 1)
        err = self.capfd.readouterr().err
        where = f"{self.label}: wormsim {' '.join(argv)}: exit {code}\n{err[-3000:]}"
        assert code in (0, 2, 3), where
        assert "Traceback" not in err and "internal error" not in err, where
        lines = [s for s in err.splitlines() if s.strip()]
        if code == 2:  # `error: ...` naming the field (several problems: one line each after it)
            first = next((s for s in lines if s.startswith("error: ")), "")
            assert FIELD.search(first), where
        if code == 3:
            assert lines and lines[-1].startswith("simulation failed: "), where
            MESSAGES.append(f"{self.label} {name}: {lines[-1]}")
        self.codes[name] = code
        if code:
            self.messages[name] = lines[-1][:2000] if lines else ""
        return code


MESSAGES: list[str] = []  # the exit-3 messages (printed by the non-vacuity tests)
OUTCOMES: dict[int, dict[str, int]] = {}

ALL = ("check", "wedge", "torsional", "import", "contact3d", "rate", "rate_fe", "mesh", "model", "sweep")


def use_every_command(index: int, folder: Path, capfd, commands=ALL, stiffness: str = "hertz") -> dict[str, int]:
    """init, the template edited to gear `index`, then `commands` (names of ALL) on it; returns their exit codes."""
    d = draw(index)
    user = User(folder, capfd, f"gear {index} {json.dumps(d, separators=(',', ':'))}")
    g = folder / "g.yaml"
    assert user("init", "init", str(g)) == 0
    sc = yaml_load(g.read_text())  # YAML 1.2 keys (`on:` is a key, not true), as wormsim reads the file
    sc["gear"] = {k: v for k, v in d["gear"].items() if v is not None}
    sc["materials"] = d["materials"]
    sc["rating"] = d["rating"]
    sc["drive"]["speed_rpm"] = d["speed_rpm"]
    sc["load"]["torque_nm"] = d["load_nm"]
    sc["simulation"]["duration_s"] = 0.2
    if stiffness != "teeth":  # the default is the teeth's FE compliance (10-30 s per new gear)
        sc["contact"]["stiffness_model"] = stiffness
    g.write_text(yaml.safe_dump(sc, sort_keys=False))
    out = str(folder / "out")
    if "check" in commands:
        user("check", "check", str(g))
    if "wedge" in commands:
        user("wedge", "run", str(g), "--out", out + "/wedge", "--no-progress", "--set", "model=wedge")
    if "torsional" in commands or "import" in commands:
        rexs = folder / "stage.rexs"
        code = user("torsional", "run", str(g), "--out", out + "/torsional", "--no-progress", "--rexs", str(rexs))
        if code == 0 and "import" in commands:
            assert rexs.exists(), user.label
            imported = folder / "imported.yaml"
            if user("import", "import", str(rexs), "--out", str(imported)) == 0:
                user("import_check", "check", str(imported))
    if "contact3d" in commands:
        user(
            "contact3d",
            *("run", str(g), "--out", out + "/contact3d", "--no-progress"),
            *("--set", "model=contact3d"),
            *("--set", "simulation.resolution=coarse", "--set", "simulation.duration_s=0.03"),
            *("--set", "drive.ramp_s=0.005", "--set", "load.ramp_s=0.005"),
            limit_s=600,
        )
    if "rate" in commands:
        user("rate", "rate", str(g), "--out", out + "/rate")
    if "rate_fe" in commands:
        # two mesh positions instead of 6: the same FE mesh of the tooth (gmsh), a third of the solves
        user("rate_fe", "rate", str(g), "--out", out + "/rate_fe", "--fe", "--set", "rating.fe_positions=2")
    if "mesh" in commands:
        user("mesh", "mesh", str(g), "--out", out + "/mesh")
    if "model" in commands:
        user("model", "model", str(g), "--out", out + "/model")
    if "sweep" in commands:
        sw = folder / "sweep.yaml"
        load = d["load_nm"]
        spec = {
            "name": "two",
            "base": "g.yaml",
            "set": {"model": "torsional", "simulation.duration_s": 0.1},
            "grid": {"load.torque_nm": [round(0.5 * load, 4), load]},
        }
        sw.write_text(yaml.safe_dump(spec, sort_keys=False))
        if user("sweep", "sweep", str(sw), "--out", out + "/sweep", "--workers", "1", "--no-progress") == 0:
            for name in ("sweep.csv", "sweep.json"):  # a failed point's message
                text = (folder / "out" / "sweep" / name).read_text()
                assert "internal error" not in text, (user.label, name, text[-3000:])
    if os.environ.get("WORMSIM_COMMANDS_LOG"):  # one JSON line per gear: exit codes, wall times, exit-3 messages
        with open(os.environ["WORMSIM_COMMANDS_LOG"], "a") as f:
            f.write(
                json.dumps(
                    {"index": index, "codes": user.codes, "wall_s": user.wall_s, "messages": user.messages, "data": d}
                )
                + "\n"
            )
    return user.codes


# `make test`: a handful of gears, each command on at least one (the FE mesher and contact3d cost the most)
CI_GEARS = {
    0: ("check", "wedge", "torsional", "import", "rate", "rate_fe"),
    1: ("check", "torsional", "contact3d", "rate"),
    21: ("check", "torsional", "mesh", "model", "sweep"),  # a 4x26 ZA gear: mesh and model cost less on a small wheel
}


@pytest.mark.parametrize("index", sorted(CI_GEARS))
def test_random_gear_every_command_exits_0_2_or_3(index, tmp_path, capfd):
    OUTCOMES[index] = use_every_command(index, tmp_path, capfd, CI_GEARS[index])


def test_random_gears_mostly_run():
    """Not vacuous: the CI gears pass check and run at torsional (exit 0; measured: all three)."""
    if len(OUTCOMES) < len(CI_GEARS):
        pytest.skip("runs after test_random_gear_every_command_exits_0_2_or_3")
    ok = [i for i, c in OUTCOMES.items() if c.get("check") == 0 and c.get("torsional") == 0]
    assert len(ok) == len(CI_GEARS), (OUTCOMES, MESSAGES)


LONG_OUTCOMES: dict[int, dict[str, int]] = {}


@pytest.mark.parametrize("index", range(100, 100 + LONG_GEARS))
def test_random_gear_every_command_exits_0_2_or_3_long(index, tmp_path, capfd):
    stiffness = "teeth" if index % TEETH_EVERY == 0 else "hertz"
    LONG_OUTCOMES[index] = use_every_command(index, tmp_path, capfd, stiffness=stiffness)


def test_random_gears_mostly_run_long():
    """Not vacuous: many long-test gears run (exit 0 from check, torsional and contact3d): measured 59 of 98; the
    rest are refused by the geometry checks (exit 2), mostly a face width past the root torus's limit, a ZK tool that
    undercuts the thread, pointed or undercut teeth."""
    if len(LONG_OUTCOMES) < LONG_GEARS:
        pytest.skip("runs after test_random_gear_every_command_exits_0_2_or_3_long")
    ok = [i for i, c in LONG_OUTCOMES.items() if all(c.get(k) == 0 for k in ("check", "torsional", "contact3d"))]
    assert len(ok) >= 40, (len(ok), MESSAGES)


def test_the_steep_4x38_za_gear_runs_at_contact3d(tmp_path, capfd):
    """The issue's exit 1: a 4/38 ZA gear, q 6, alpha_n 10 deg (gamma 33.7 deg) at contact3d. A contact with no
    contact-line length left in its slice (L = 0) divided by zero in hertz's p_H (ZeroDivisionError in the compiled
    rows, with either stiffness model); it has no p_H now. The user's commands: init, then run with --set."""
    user = User(tmp_path, capfd, "4x38 ZA")
    g = str(tmp_path / "g.yaml")
    assert user("init", "init", g) == 0
    sets = {
        "model": "contact3d",
        "gear.profile": "ZA",
        "gear.worm_starts": 4,
        "gear.wheel_teeth": 38,
        "gear.axial_module_mm": 1,
        "gear.diameter_quotient": 6,
        "gear.normal_pressure_angle_deg": 10,
        "gear.face_width_mm": "null",
        "simulation.resolution": "coarse",
        "drive.speed_rpm": 3000,
        "simulation.duration_s": 0.05,
        "load.torque_nm": 5,
        "contact.stiffness_model": "hertz",  # the FE compliance's cost apart; the teeth's stiffness failed alike
    }
    argv = [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
    assert user("run", "run", g, "--out", str(tmp_path / "o"), "--no-progress", *argv) == 0
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["status"] == "ok" and math.isfinite(s["contact_pressure_max_mpa"]), s["contact_pressure_max_mpa"]
