"""A normal (non-editable) `pip install .` into a fresh virtual environment works from another directory: the models
and scenarios ship as package data (wormsim.models, wormsim.scenarios) and nothing reads the source tree.

The fresh venv reuses the test environment's installed dependencies through a .pth line (offline and fast); the
package itself is built from a copy of the repository and installed without dependencies.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

from tests.conftest import ROOT

SKIP = shutil.ignore_patterns(
    ".venv",
    ".git",
    "out",
    "build",
    "*.egg-info",
    "__pycache__",
    ".pytest_cache",
    ".hypothesis",
    ".cache",
    ".mypy_cache",
    ".ruff_cache",
)


def _fresh_install(tmp: Path) -> Path:
    src, env = tmp / "src", tmp / "venv"
    shutil.copytree(ROOT, src, ignore=SKIP)
    venv.create(env, with_pip=False)
    py = env / "bin" / "python"
    site = subprocess.run(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    # the dependencies of the test environment, as a plain path (its .pth files, e.g. an editable wormsim, are not
    # processed from there)
    Path(site, "_test_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(py),
            "install",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            str(src),
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    shutil.rmtree(src)
    return env


def test_non_editable_install_runs_from_another_directory(tmp_path):
    env = _fresh_install(tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    exe = env / "bin" / "wormsim"
    where = subprocess.run(
        [
            str(env / "bin" / "python"),
            "-c",
            "import wormsim, wormsim.contact3d.mjcf as m, wormsim.bench.cases as c; "
            "print(wormsim.__file__); print('<mujoco' in m.TEMPLATE.read_text()); "
            "print(sorted(p.name for p in c.SCENARIOS.iterdir() if p.name.endswith('.yaml')))",
        ],
        cwd=elsewhere,
        check=True,
        capture_output=True,
        text=True,
    ).stdout.splitlines()
    assert Path(where[0]).is_relative_to(env), where[0]  # the installed copy, not the source tree
    assert where[1] == "True"  # worm_pair.xml shipped as package data
    assert "mov_1.yaml" in where[2] and "seat_motor.yaml" in where[2]
    # a run of a seed scenario given by path, and the bench's help, from a directory outside the repository
    out = elsewhere / "mov_1"
    run = subprocess.run(
        [str(exe), "run", str(ROOT / "scenarios" / "mov_1.yaml"), "--out", str(out), "--no-progress"],
        cwd=elsewhere,
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert json.loads((out / "summary.json").read_text())["status"] == "ok"
    assert (out / "timeseries.npz").exists() and (out / "report.png").exists()
    bench = subprocess.run([str(exe), "bench", "--help"], cwd=elsewhere, capture_output=True, text=True)
    assert bench.returncode == 0 and "--quick" in bench.stdout


def test_source_checkout_runs_without_installing(tmp_path):
    """`PYTHONPATH=. python -c "import wormsim; ..."` and `python -m wormsim` from a source checkout, in a clean
    environment where no wormsim is installed: the models/ and scenarios/ folders are found in the source tree."""
    env = tmp_path / "venv"
    venv.create(env, with_pip=False)
    py = str(env / "bin" / "python")
    site = subprocess.run(
        [py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    Path(site, "_test_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")  # the dependencies only
    clean = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "WORMSIM_CACHE": str(tmp_path / "cache")}
    none = subprocess.run(
        [py, "-c", "import importlib.util; print(importlib.util.find_spec('wormsim'))"],
        cwd=tmp_path,
        env=clean,
        capture_output=True,
        text=True,
    )
    assert none.stdout.strip() == "None", none.stdout + none.stderr  # not installed there
    code = (
        "import wormsim; from wormsim.runtime.data import data_dir; "
        "sc = wormsim.load_scenario('scenarios/screw_jack.yaml'); "
        "print(wormsim.__file__); print(data_dir('models')); print(sc.name)"
    )
    src = {**clean, "PYTHONPATH": "."}
    r = subprocess.run([py, "-c", code], cwd=ROOT, env=src, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    where, models, name = r.stdout.splitlines()
    assert Path(where) == ROOT / "wormsim" / "__init__.py" and Path(models) == ROOT / "models" and name == "screw_jack"
    cli = subprocess.run(
        [py, "-m", "wormsim", "check", "scenarios/screw_jack.yaml"], cwd=ROOT, env=src, capture_output=True, text=True
    )
    assert cli.returncode == 0 and "flank slices across the face" in cli.stdout, cli.stderr[-2000:]
    bad = subprocess.run(
        [py, "-m", "wormsim", "check", "scenarios/screw_jack.yaml", "--set", "gear.wheel_teeth=-1"],
        cwd=ROOT,
        env=src,
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and "wheel_teeth" in bad.stderr, bad.stderr[-2000:]
