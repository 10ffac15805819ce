"""Every flank form (ZN1, ZN2, ZK, ZC; ZA and ZI in tests/torsional/test_dynamics.py and tests/contact3d/test_seeds.py) with
the seeds' validation: ratio 0.1 %, torque balance 2 %, efficiency within 3 % of tan(gamma) / tan(gamma + rho') at
the contacts' radius (contact3d) or of the wedge law (torsional), the meshing frequency z1 n1 / 60.

Gears: the screw jack (a seed; every form) and involute_41 (another valid set; ZK and ZC at torsional). ZC's arc radius: 10 m_x on the screw jack (25 mm,
INTERFACE.md's example) and 8 m_x on involute_41; the default 5.5 m_x undercuts these unshifted wheels (refused,
docs/flank_forms.md). contact3d: short runs (screw jack at 3000 rpm so that the steady window holds > 5 mesh periods);
contact3d and `wormsim mesh` of ZN1, ZN2 and ZK are in LONG_TESTS (tests/conftest.py)."""

from __future__ import annotations

import pytest

from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from tests.contact3d.test_seeds_pieces import assert_mesh_frequency
from wormsim.contact3d.runner import simulate
from wormsim.run import run_scenario
from wormsim.scenario import load_scenario

FORMS = {
    "ZN1": ["gear.profile=ZN", "gear.zn_section=thread"],
    "ZN2": ["gear.profile=ZN", "gear.zn_section=space"],
    "ZK": ["gear.profile=ZK"],
    "ZC": ["gear.profile=ZC"],
}
# the unshifted wheels of the recorded study (docs/flank_forms.md): ZC's default profile shift 0.5 turned off
ZC_RADIUS = {
    "screw_jack": ["gear.profile_radius_mm=25", "gear.profile_shift_coefficient=0"],
    "involute_41": ["gear.profile_radius_mm=80", "gear.profile_shift_coefficient=0"],
}
CASES = [("screw_jack", f) for f in FORMS] + [("involute_41", f) for f in ("ZK", "ZC")]
_CACHE: dict = {}


def _sets(gear, form):
    return FORMS[form] + (ZC_RADIUS[gear] if form == "ZC" else [])


def torsional(gear, form, tmp_path_factory):
    key = ("t", gear, form)
    if key not in _CACHE:
        sc = load_scenario(SCENARIOS / f"{gear}.yaml", ["model=torsional", *_sets(gear, form)])
        _CACHE[key] = (run_scenario(sc, tmp_path_factory.mktemp(f"{gear}_{form}"), progress=False), sc)
    return _CACHE[key]


@pytest.mark.parametrize("gear,form", CASES)
def test_torsional_validation_per_form(gear, form, tmp_path_factory):
    s, sc = torsional(gear, form, tmp_path_factory)
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3
    assert abs(s["tangential_force_mean_n"] * derive(sc.gear).r2 / sc.load.torque_nm - 1) < 0.02
    assert abs(s["efficiency"] / s["efficiency_theory"] - 1) < 0.03


# involute_41's transmission error has a larger 2nd than 1st meshing harmonic (ZK, ZN1, ZN2 as ZI and ZA; ZC's largest
# is the 1st): the meshing line (wormsim.results.metrics.mesh_line), not the spectrum's largest peak, is z1 n1 / 60
@pytest.mark.parametrize("gear,form", CASES)
def test_torsional_mesh_frequency_per_form(gear, form, tmp_path_factory):
    s, _ = torsional(gear, form, tmp_path_factory)
    # the 0.5 % of z1 n1 / 60 (tests/contact3d/test_seeds_pieces.py's MESH_FREQUENCY_REL), on a window of >= 5 periods
    assert s["steady_window_mesh_cycles"] >= 5
    assert abs(s["mesh_frequency_hz"] / s["mesh_frequency_theory_hz"] - 1) <= 0.005, s["mesh_frequency_hz"]


CONTACT3D = [
    "drive.speed_rpm=3000",
    "drive.ramp_s=0.02",
    "load.ramp_s=0.02",
    "simulation.duration_s=0.2",
    "simulation.resolution=medium",
    "contact.geometry=flanks",
]


@pytest.mark.parametrize("name", [f"contact3d_{f}" for f in FORMS])
def test_contact3d_validation_per_form(name):
    """ZN1, ZN2 and ZK in LONG_TESTS (about 5 s each with the geometry cached, 15-45 s without)."""
    gear = "screw_jack"
    sc = load_scenario(SCENARIOS / f"{gear}.yaml", CONTACT3D + _sets(gear, name.removeprefix("contact3d_")))
    s = simulate(sc).summary
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3
    assert abs(s["tangential_force_mean_n"] * derive(sc.gear).r2 / sc.load.torque_nm - 1) < 0.02
    assert abs(s["efficiency"] / s["efficiency_theory_at_contact_radius"] - 1) < 0.03
    assert_mesh_frequency(s, "mesh_frequency_hz")


@pytest.mark.parametrize("name", [f"mesh_{f}" for f in FORMS])
def test_mesh_command_writes_each_form(name, tmp_path, monkeypatch, capsys):
    """`wormsim mesh` writes each form's worm and wheel (watertight); ZC with the arc radius 10 m_x on the screw jack.
    ZN1, ZN2 and ZK in LONG_TESTS."""
    import trimesh

    from wormsim.cli import main

    monkeypatch.setenv("WORMSIM_CACHE", str(tmp_path / "cache"))
    form = name.removeprefix("mesh_")
    sets = [a for s in _sets("screw_jack", form) + ["simulation.resolution=coarse"] for a in ("--set", s)]
    out = tmp_path / "out"
    assert main(["mesh", str(SCENARIOS / "screw_jack.yaml"), "--out", str(out), *sets]) == 0
    for part in ("worm", "wheel"):
        m = trimesh.load(out / f"{part}.stl")
        assert m.is_watertight and m.volume > 0


def test_zc_default_arc_undercuts_the_screw_jack_unshifted(tmp_path, capsys):
    """ZC at the default arc radius 5.5 m_x undercuts the screw jack's wheel without profile shift (75 % > 60 %,
    docs/flank_forms.md): exit 2, one line naming gear.profile_radius_mm and gear.profile_shift_coefficient."""
    from wormsim.cli import main

    sets = ["--set", "gear.profile=ZC", "--set", "gear.profile_shift_coefficient=0"]
    code = main(["mesh", str(SCENARIOS / "screw_jack.yaml"), "--out", str(tmp_path / "o"), *sets])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1
    assert "removes 75 %" in err and "gear.profile_radius_mm" in err and "gear.profile_shift_coefficient" in err


@pytest.mark.parametrize("gear", ["involute_41", "screw_jack"])
def test_zc_runs_at_its_defaults(gear, tmp_path_factory):
    """ZC with nothing but gear.profile=ZC: the default arc radius 5.5 m_x with the default profile shift x2 = 0.5
    (docs/flank_forms.md) on involute_41 (1x41, alpha_n 20 deg: 63 % undercut unshifted) and the screw jack; the
    torsional validation holds (ratio, F_t2 = T2 / r2, efficiency against the wedge law at gamma_m)."""
    sc = load_scenario(SCENARIOS / f"{gear}.yaml", ["model=torsional", "gear.profile=ZC"])
    g = derive(sc.gear)
    assert g.x2 == 0.5 and g.profile_radius == pytest.approx(5.5 * g.m_x)
    s = run_scenario(sc, tmp_path_factory.mktemp(f"zc_default_{gear}"), progress=False)
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3
    assert abs(s["tangential_force_mean_n"] * g.r2 / sc.load.torque_nm - 1) < 0.02
    assert abs(s["efficiency"] / s["efficiency_theory"] - 1) < 0.03
