"""FE root stress (wormsim.rating.fe_root): the solver against a closed form, linearity in the load, the h vs h/2
mesh convergence on a seed (long), and `wormsim rate --fe`."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from tests.conftest import SCENARIOS
from wormsim import cli
from wormsim.physics.geometry import derive
from wormsim.rating import fe_root
from wormsim.scenario import load_scenario


def _box(lx: float, ly: float, lz: float, size: float) -> tuple[np.ndarray, np.ndarray]:
    import gmsh

    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.addBox(0, 0, 0, lx, ly, lz)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", size)
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(3)
    finally:
        gmsh.finalize()
    P = np.asarray(xyz).reshape(-1, 3)
    order = np.empty(int(tags.max()) + 1, dtype=np.int64)
    order[np.asarray(tags, dtype=np.int64)] = np.arange(len(tags))
    return P, order[np.asarray(conn[0], dtype=np.int64).reshape(-1, 4)]


def test_cantilever_against_beam_theory():
    """A clamped steel bar 100 x 10 x 10 mm with an end load of 100 N: Euler-Bernoulli bending stress
    sigma_xx = F (L - x) y / I (I = b h^3 / 12) at the element centroids of the middle fifth (Saint-Venant: away from
    the clamp and the load), and tip deflection F L^3 / (3 E I) (+ the shear term F L / (k G A), k = 5/6)."""
    L, h, b, F, E, nu = 0.1, 0.01, 0.01, 100.0, 210e9, 0.3
    P, T = _box(L, h, b, 3.4e-3)
    used = np.unique(T)
    remap = -np.ones(len(P), dtype=np.int64)
    remap[used] = np.arange(len(used))
    P, T = P[used], remap[T]
    tip = np.where(P[:, 0] > L - 1e-9)[0]
    forces = np.zeros((len(tip), 3))
    forces[:, 1] = -F / len(tip)
    sol = fe_root.solve_elastic(P, T, E, nu, lambda x: x[0] < 1e-9, [(tip, forces)])
    I = b * h**3 / 12
    c = sol.centroids
    mid = (c[:, 0] > 0.4 * L) & (c[:, 0] < 0.6 * L)
    beam = -F * (L - c[mid, 0]) * (c[mid, 1] - h / 2) / I * -1.0  # tension on top (y = h) under a downward load
    fe = sol.stress[0][mid, 0, 0]
    smax = F * 0.5 * L * (h / 2) / I
    assert np.max(np.abs(fe - beam)) / smax < 0.03
    g_mod = E / (2 * (1 + nu))
    delta = F * L**3 / (3 * E * I) + F * L / (5 / 6 * g_mod * b * h)
    uy_tip = -sol.displacement[0][tip, 1].mean()
    assert uy_tip == pytest.approx(delta, rel=0.03)


def _screw_jack():
    sc = load_scenario(SCENARIOS / "screw_jack.yaml")
    return sc, derive(sc.gear)


@pytest.fixture(scope="module")
def fe_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("fe-cache")


def test_root_stress_is_linear_in_the_load(fe_cache, monkeypatch):
    monkeypatch.setenv("WORMSIM_CACHE", str(fe_cache))
    sc, g = _screw_jack()
    one, two = fe_root.root_stress_cases(g, 130e9, 0.25, 1, [12.0, 24.0], 2, density=1)
    assert one["root_stress_max_mpa"] > 0
    # linear elasticity: the stress scales with the load, 24 / 12 N m = 2
    assert two["root_stress_max_mpa"] == pytest.approx(2 * one["root_stress_max_mpa"], rel=1e-6)
    assert two["position_mm"] == pytest.approx(one["position_mm"])


def test_contact_loads_carry_the_tooth_share_of_the_torque():
    """The forces on the FE tooth: their torque about the wheel axis is the tooth's share of T2 (at most T2), and
    summed over the teeth in contact the load law gives T2 back (the share per tooth from the same lines)."""
    sc, g = _screw_jack()
    for pts, frc in fe_root.contact_loads(g, 1, 12.0, 6):
        torque = float(np.sum(np.cross(pts, frc)[:, 2]))
        # 12.0 N m: the T2 passed to contact_loads above; one tooth carries at most all of it
        assert 0 < abs(torque) <= 12.0 * (1 + 1e-9)


@pytest.mark.long
def test_root_stress_mesh_convergence():
    """h vs h/2 on the screw jack (mesh density 1 and 2, 3 positions): the max root stress (the ball average of
    fe_root's docstring) within 5 % (the issue's criterion)."""
    sc, g = _screw_jack()
    h = fe_root.root_stress(g, 130e9, 0.25, 1, 12.0, 3, density=1)
    h2 = fe_root.root_stress(g, 130e9, 0.25, 1, 12.0, 3, density=2)
    assert h2["root_stress_max_mpa"] == pytest.approx(h["root_stress_max_mpa"], rel=0.05)


@pytest.mark.long
@pytest.mark.xfail(
    strict=True,
    reason="at the default 6 positions the peak sits near an end face, where density 1 resolves least: screw jack "
    "7.85 MPa at density 1 against 7.11 MPa at density 2 (+10 %, docs/decisions/0027-fe-root-density-1.md)",
)
def test_root_stress_mesh_convergence_at_the_default_positions():
    """h vs h/2 on the screw jack at rating.fe_positions' default (6): within 5 %."""
    from wormsim.scenario import Rating

    positions = Rating().fe_positions
    sc, g = _screw_jack()
    h = fe_root.root_stress(g, 130e9, 0.25, 1, 12.0, positions, density=1)
    h2 = fe_root.root_stress(g, 130e9, 0.25, 1, 12.0, positions, density=2)
    assert h2["root_stress_max_mpa"] == pytest.approx(h["root_stress_max_mpa"], rel=0.05)


def test_rate_fe_writes_the_root_stress(tmp_path, fe_cache, monkeypatch, capsys):
    monkeypatch.setenv("WORMSIM_CACHE", str(fe_cache))
    code = cli.main(
        [
            "rate",
            str(SCENARIOS / "screw_jack.yaml"),
            "--out",
            str(tmp_path / "out"),
            "--fe",
            "--set",
            "rating.fe_mesh_density=1",
            "--set",
            "rating.fe_positions=2",
            "--set",
            "rating.root_stress_limit_mpa=60",
        ]
    )
    assert code == 0
    out = json.loads((tmp_path / "out" / "rating.json").read_text())
    assert out["root_stress_max_mpa"] > 0 and out["root_stress_range_mpa"] > 0
    # safety = limit / stress with rating.root_stress_limit_mpa=60 set above
    assert out["safety_root_sim"] == pytest.approx(60 / out["root_stress_max_mpa"])
    assert math.isfinite(out["fe_root"]["position_mm"][0])
    assert "FE root stress" in (tmp_path / "out" / "rating.md").read_text()
    assert "safety_root_sim" in capsys.readouterr().out  # the terminal summary lists it with --fe


def test_root_stress_limit_defaults_to_the_material_row():
    """safety_root_sim's limit: the given rating.root_stress_limit_mpa, else 2 tau_FlimT of the wheel material's row
    (Tresca), and none for POM (no tau_FlimT in the table)."""
    from wormsim.rating.materials import WHEEL_MATERIALS

    assert fe_root.root_stress_limit_mpa(60.0, "GJL-250")[0] == 60.0
    assert fe_root.root_stress_limit_mpa(None, "GJL-250")[0] == 2 * WHEEL_MATERIALS["GJL-250"].tau_flim_t_mpa
    limit, why = fe_root.root_stress_limit_mpa(None, "POM")
    assert limit is None and "POM" in why


def test_summary_with_fe_root_stress_has_the_simulated_safety_factors(fe_cache, monkeypatch):
    """`rating: {root_stress: fe}` at contact3d: the summary keys carry root_stress_max_mpa, safety_root_sim (limit
    2 tau_FlimT of GJL-250 by default) and safety_pitting_sim from the simulated mean Hertz pressure (sigma_H, the
    run's contact_pressure_mean_mpa)."""
    from wormsim.rating.summary import pitting_limit_mpa, rating_before_run, summary_keys

    monkeypatch.setenv("WORMSIM_CACHE", str(fe_cache))
    sc = load_scenario(
        SCENARIOS / "screw_jack.yaml",
        ["rating.root_stress=fe", "rating.wheel_material=GJL-250", "rating.fe_positions=2"],
    )
    rating = rating_before_run(sc)
    keys = summary_keys(sc, rating, {"contact_pressure_mean_mpa": 150.0})
    assert keys["root_stress_max_mpa"] > 0
    assert keys["safety_root_sim"] == pytest.approx(2 * 70.0 / keys["root_stress_max_mpa"])  # GJL-250: 70 MPa
    assert keys["safety_pitting_sim"] == pytest.approx(pitting_limit_mpa(rating) / 150.0)
