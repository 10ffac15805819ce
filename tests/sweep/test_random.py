"""The sweep file's random block with list draws (size: N, one value per wheel tooth) and the tolerance study's
sweep files (studies/tolerance_grade.py, issue 12): reproducible draws within the limits, bad input exit 2."""

import importlib
from pathlib import Path

import pytest

from wormsim import cli
from wormsim.sweep import load_sweep
from wormsim.sweep.spec import SweepFile, expand

ROOT = Path(__file__).resolve().parents[2]
SCREW_JACK = ROOT / "scenarios" / "screw_jack.yaml"


@pytest.fixture(autouse=True)
def _no_external_scheduler(monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)


def _spec(vary: dict, n: int = 5, seed: int = 3) -> SweepFile:
    return SweepFile.model_validate({"name": "t", "base": "x", "random": {"n": n, "seed": seed, "vary": vary}})


def test_list_draws_per_point_reproducible_and_within_bounds():
    vary = {"a.b": {"uniform": [-2.0, 2.0], "size": 7}, "c.d": {"normal": [1.0, 0.5]}}
    pts = expand(_spec(vary))
    assert len(pts) == 5
    assert all(isinstance(p["a.b"], list) and len(p["a.b"]) == 7 for p in pts)
    assert all(-2.0 <= v <= 2.0 for p in pts for v in p["a.b"])
    assert all(isinstance(p["c.d"], float) for p in pts)
    assert len({tuple(p["a.b"]) for p in pts}) == 5  # a fresh list per point
    assert pts == expand(_spec(vary))  # the seed fixes the draws
    assert pts != expand(_spec(vary, seed=4))


BAD = {
    "size_zero": ("{uniform: [-1, 1], size: 0}", "greater than or equal to 1"),
    "low_above_high": ("{uniform: [1, -1]}", "low must be <= high"),
    "size_only": ("{size: 3}", "expected {uniform: [low, high]} or {normal: [mean, sd]}"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_random_block_exits_2_naming_the_field(case, tmp_path, capsys):
    body, expected = BAD[case]
    f = tmp_path / "s.yaml"
    f.write_text(
        f"name: bad\nbase: {SCREW_JACK}\nrandom: {{n: 3, vary: {{errors.wheel_pitch_deviation_um: {body}}}}}\n"
    )
    assert cli.main(["sweep", str(f), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "errors.wheel_pitch_deviation_um" in err and expected in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def _tolerance_module():
    return importlib.import_module("studies.tolerance_grade")


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor"])
def test_tolerance_sweep_files_match_the_grade_formulas(name):
    """The shipped sweep file is what the script writes for grade 8, and its 100 points stay inside the grade:
    runouts in [0, F_r / 2], tooth shifts within f_pT / 2 (single pitch deviations within f_pT), one shift per
    wheel tooth."""
    mod = _tolerance_module()
    path = ROOT / "studies" / f"{name}_tolerance.yaml"
    assert path.read_text() == mod.sweep_yaml(name, 8, 100, 12)
    t = mod.tolerances(name, 8)
    sw = load_sweep(path)
    assert len(sw.points) == 100
    for p in sw.points:
        e = p.scenario.errors
        assert 0 <= e.wheel_runout_mm <= t["wheel_runout_mm"] and 0 <= e.worm_runout_mm <= t["worm_runout_mm"]
        assert abs(e.center_distance_mm) <= t["center_distance_mm"]
        assert abs(e.shaft_angle_deg) <= t["shaft_angle_deg"]
        assert len(e.wheel_pitch_deviation_um) == t["inputs"]["z2"]
        assert max(abs(s) for s in e.wheel_pitch_deviation_um) <= t["tooth_shift_um"]
    # the draws cover the band, not a corner of it
    angles = [p.scenario.errors.shaft_angle_deg for p in sw.points]
    assert max(angles) > 0.8 * t["shaft_angle_deg"] and min(angles) < -0.8 * t["shaft_angle_deg"]
