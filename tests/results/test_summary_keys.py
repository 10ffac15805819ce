"""The output-key reference (wormsim.results.summary_keys, docs/outputs.md): every key a level writes has an entry, the doc is
current, and forces carry one sign convention in summary.json and the time series."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import ROOT, SCENARIOS
from tools import outputs_doc
from wormsim.results import summary_keys as outputs
from wormsim.run import run_scenario
from wormsim.scenario import load_scenario

MINIMAL = ROOT / "tests" / "assets" / "minimal_contact3d.yaml"
SHORT = {
    # seed 000's MOV case as it is (0.3 s simulated, under a second)
    "wedge": (SCENARIOS / "mov_1.yaml", []),
    # the wedge derived from the minimal gear (no wedge: block)
    "wedge-derived": (MINIMAL, ["model=wedge", "simulation.duration_s=0.05"]),
    # the minimal gear at torsional, with an assembly error (the kinematic TCA's keys: backlash, kinematic TE)
    "torsional": (
        MINIMAL,
        ["model=torsional", "simulation.duration_s=0.05", "errors.center_distance_mm=0.01"],
    ),
    # contact3d: 0.012 s holds the start-up and a short steady window (coarse pieces are not built for flanks)
    "contact3d": (MINIMAL, ["simulation.duration_s=0.012", "simulation.resolution=coarse"]),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for level, (path, sets) in SHORT.items():
        d = tmp_path_factory.mktemp(level)
        summary = run_scenario(load_scenario(path, sets), d, progress=False)
        out[level] = (summary, dict(np.load(d / "timeseries.npz")))
    return out


def test_docs_outputs_md_is_current():
    text = (ROOT / "docs" / "outputs.md").read_text()
    assert text == outputs_doc.markdown(), "docs/outputs.md is stale: python -m tools.outputs_doc > docs/outputs.md"


def test_every_table_entry_names_known_levels_and_a_unit():
    for name, k in outputs.KEYS.items():
        assert k.levels and set(k.levels) <= set(outputs.ALL), name
        assert k.unit and k.meaning, name


@pytest.mark.parametrize("level", list(SHORT))
def test_no_level_writes_a_key_without_an_entry(runs, level):
    summary, _ = runs[level]
    assert summary["status"] == "ok"
    assert outputs.undocumented(summary) == []
    for key in summary:  # the table's levels are right too: no key turns up at a level its entry does not name
        assert summary["model"] in outputs.KEYS[key].levels, key
    series = runs[level][1]
    for key in series:  # the time series too
        assert key in outputs.SERIES and summary["model"] in outputs.SERIES[key][0], key


@pytest.mark.parametrize("level", list(SHORT))
def test_every_level_reports_self_locking_and_backdriving(runs, level):
    s, _ = runs[level]
    for key in ("self_locking", "self_locking_dynamic", "efficiency_backdrive", "lead_angle_deg"):
        assert key in s, key
    g, rho = math.radians(s["lead_angle_deg"]), math.radians(s["friction_angle_dynamic_deg"])
    # DIN 3975-2: eta' = tan(gamma - rho') / tan(gamma), 0 when rho' >= gamma
    expected = max(math.tan(g - rho), 0.0) / math.tan(g)
    assert s["efficiency_backdrive"] == pytest.approx(expected, rel=1e-12)
    assert s["self_locking_dynamic"] == (rho >= g)


@pytest.mark.parametrize("level", ["wedge-derived", "torsional", "contact3d"])
def test_summary_and_timeseries_forces_agree_in_sign_and_value(runs, level):
    """A forward run (right-hand worm driving at positive speed): the series' steady-window means are positive
    (docs/outputs.md, Force signs) and equal the summary's magnitudes."""
    s, S = runs[level]
    t0, t1 = s["steady_window_s"]
    sl = (S["t_s"] >= t0 - 1e-12) & (S["t_s"] <= t1 + 1e-12)
    for comp in ("tangential", "radial", "axial"):
        mean = float(np.mean(S[f"{comp}_force_n"][sl]))
        assert mean > 0, (comp, mean)
        # contact3d's series are the resultant's components; its headline F_r2, F_a2 are DIN 3975's (docs/outputs.md,
        # "Force keys"): the line of centres' radial series and T1 / r1
        key = (
            f"{comp}_force_resultant_mean_n"
            if level == "contact3d" and comp != "tangential"
            else f"{comp}_force_mean_n"
        )
        assert mean == pytest.approx(s[key], rel=1e-9), comp
    if level == "contact3d":
        lc = float(np.mean(S["radial_force_line_of_centres_n"][sl]))
        assert lc > 0 and lc == pytest.approx(s["radial_force_mean_n"], rel=1e-9)


def test_a_left_hand_worm_gives_the_same_force_signs_at_torsional_and_contact3d():
    """Left hand: the wheel turns negative, F_t2 < 0 along the wheel's positive sense, F_a2 with F_t2's sign
    (F_a2 = F_t2 tan(gamma + rho'), DIN 3975-2), F_r2 separating (> 0): the same signs at both levels."""
    from wormsim.run import simulate

    means = {}
    for level, sets in (
        ("torsional", ["simulation.duration_s=0.03"]),
        ("contact3d", ["simulation.duration_s=0.015", "simulation.resolution=coarse"]),
    ):
        r = simulate(load_scenario(MINIMAL, ["gear.hand=left", f"model={level}", *sets]))
        t0, t1 = r.summary["steady_window_s"]
        sl = (r.series["t_s"] >= t0) & (r.series["t_s"] <= t1)
        means[level] = [float(np.mean(r.series[f"{c}_force_n"][sl])) for c in ("tangential", "radial", "axial")]
    for level, (ft, fr, fa) in means.items():
        assert ft < 0 and fr > 0 and fa < 0, (level, ft, fr, fa)


def test_level_summary_merges_in_order_and_refuses_a_key_without_the_levels_entry():
    """wormsim.results.summary_keys.level_summary, every level's summary builder: later groups replace earlier keys; a key with
    no entry, or whose entry does not name the level, raises KeyError naming it."""
    s = outputs.level_summary("torsional", {"ratio": 1.0, "efficiency": 0.5}, {"efficiency": 0.6})
    assert s == {"ratio": 1.0, "efficiency": 0.6}
    with pytest.raises(KeyError, match="no_such_key"):
        outputs.level_summary("contact3d", {"ratio": 1.0}, {"no_such_key": 1})
    wedge_only = next(k for k, e in outputs.KEYS.items() if e.levels == ("wedge",))
    with pytest.raises(KeyError, match=wedge_only):
        outputs.level_summary("torsional", {wedge_only: 1.0})
    assert outputs.level_summary("wedge", {wedge_only: 1.0}) == {wedge_only: 1.0}
