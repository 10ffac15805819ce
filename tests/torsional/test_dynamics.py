"""The torsional fidelity level (wormsim.torsional.dynamics) and its mesh stiffness TCA (wormsim.tooth.mesh_stiffness).

Closed forms checked against: ratio z2 / z1; meshing frequency z1 n1 / 60 (seed 001); torque balance
F_t2 r2 = load torque (statics); efficiency tan g / tan(g + rho') and tan(g - rho') / tan g with
rho' = atan(mu / cos alpha_n) (DIN 3975, seed 000); self-locking for rho' > gamma (seed 000).
"""

import json
import math

import numpy as np
import pytest

from meshgen.geometry import derive
from tests.conftest import ROOT
from wormsim.physics.friction import friction_coefficient, friction_coefficient_scalar
from wormsim.physics.gear_theory import effective_modulus_pa
from wormsim.run import run_scenario
from wormsim.scenario import load_scenario
from wormsim.tooth import mesh_stiffness as M
from wormsim.tooth import stiffness as ST
from wormsim.torsional import dynamics as torsional

SEEDS = ("seat_motor", "screw_jack", "involute_41")
SUMMARY_KEYS = (
    "ratio",
    "ratio_theory",
    "mesh_frequency_hz",
    "mesh_frequency_theory_hz",
    "tangential_force_mean_n",
    "tangential_force_p2p_n",
    "radial_force_mean_n",
    "axial_force_mean_n",
    "worm_torque_mean_nm",
    "wheel_torque_mean_nm",
    "worm_speed_mean_rpm",
    "wheel_speed_mean_rpm",
    "efficiency",
    "steady_window_s",
    "timestep_s",
)


def scen(name, *overrides):
    return load_scenario(ROOT / "scenarios" / f"{name}.yaml", ["model=torsional", *overrides])


@pytest.fixture(scope="module")
def seed_runs(tmp_path_factory):
    """Each seed scenario FILE run at --set model=torsional through the runner (files and summary)."""
    out = {}
    for name in SEEDS:
        d = tmp_path_factory.mktemp(name)
        out[name] = (run_scenario(scen(name), d, progress=False), d)
    return out


def rho_prime(summary, g):
    return math.atan(summary["friction_coefficient_mean"] / math.cos(g.alpha_n))


@pytest.mark.parametrize("name", SEEDS)
def test_seed_scenario_runs_at_torsional_with_contact3d_keys(seed_runs, name):
    summary, d = seed_runs[name]
    assert summary["status"] == "ok" and summary["model"] == "torsional"
    for f in ("summary.json", "timeseries.npz", "report.png", "recording.rrd"):
        assert (d / f).is_file(), f
    on_disk = json.loads((d / "summary.json").read_text())
    for k in SUMMARY_KEYS:
        assert k in on_disk, k
    assert np.load(d / "timeseries.npz")["t_s"][-1] == pytest.approx(summary["sim_time_s"])


@pytest.mark.parametrize("name", SEEDS)
def test_ratio_within_0p1_percent(seed_runs, name):
    s = seed_runs[name][0]
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3


@pytest.mark.parametrize("name", SEEDS)
def test_torque_balance_ft2_r2_equals_load(seed_runs, name):
    s = seed_runs[name][0]
    sc = scen(name)
    g = derive(sc.gear)
    # the mesh spring's mean force (not the load command) times r2 carries the load: statics of the wheel, 2 %
    assert abs(s["tangential_force_mean_n"] * g.r2 / sc.load.torque_nm - 1) < 0.02


@pytest.mark.parametrize("name", SEEDS)
def test_efficiency_is_the_wedge_law(seed_runs, name):
    """The torsional level is built on the wedge law and the DIN 3975 forces: this checks that the element and the
    metrics implement them (a wrong sign or angle fails), not the physics; the independent check of the efficiency
    and the forces is contact3d on the same gear (tests/contact3d/test_seeds.py::
    test_torsional_agrees_with_contact3d_on_the_same_gear)."""
    s = seed_runs[name][0]
    g = derive(scen(name).gear)
    eta = math.tan(g.gamma) / math.tan(g.gamma + rho_prime(s, g))
    assert abs(s["efficiency"] / eta - 1) < 0.03
    # and the worm torque is F_t2 r1 tan(g + rho') (DIN 3975 forces)
    assert s["axial_force_mean_n"] == pytest.approx(
        s["tangential_force_mean_n"] * math.tan(g.gamma + rho_prime(s, g)), rel=0.02
    )


@pytest.mark.parametrize(
    "name",
    [
        "seat_motor",
        "screw_jack",
        # its TCA's k(theta) has a larger 2nd than 1st harmonic (0.032 against 0.022 of the mean): the meshing line,
        # not the spectrum's largest peak (wormsim.results.metrics.mesh_line)
        "involute_41",
    ],
)
def test_mesh_frequency_is_z1_n1_over_60(seed_runs, name):
    s = seed_runs[name][0]
    # 0.5 % of z1 n1 / 60 (seed 001), the meshing line refined on the continuous spectrum (wormsim.results.metrics.mesh_line)
    assert abs(s["mesh_frequency_hz"] / s["mesh_frequency_theory_hz"] - 1) <= 0.005, (
        s["mesh_frequency_hz"],
        s["mesh_frequency_theory_hz"],
    )


def test_backdriving_efficiency_when_not_self_locking():
    """Screw jack driven from the wheel (rho' = 3.05 deg < gamma = 5.71 deg): eta' = tan(g - rho') / tan g."""
    sc = scen(
        "screw_jack",
        "drive.on=wheel",
        "drive.speed_rpm=55.4",
        "drive.ramp_s=0.05",
        "load.on=worm",
        "load.torque_nm=0.2",
        "simulation.duration_s=0.3",
    )
    r = torsional.simulate(sc)
    g = derive(sc.gear)
    eta = math.tan(g.gamma - rho_prime(r.summary, g)) / math.tan(g.gamma)
    assert abs(r.summary["efficiency"] / eta - 1) < 0.03
    assert abs(r.summary["ratio"] / g.ratio - 1) < 1e-3


def _wheel_torque_worm_free(friction):
    sc = scen(
        "seat_motor",
        "drive.on=wheel",
        "drive.speed_rpm=null",
        "drive.torque_nm=2.0",
        "drive.ramp_s=0.01",
        "load.on=worm",
        "load.torque_nm=0",
        "load.ramp_s=0",
        f"contact.friction={friction}",
        "contact.friction_static=null",
        "contact.friction_dynamic=null",
        "simulation.duration_s=0.2",
    )
    return torsional.simulate(sc)


def test_self_locking_worm_creeps():
    """rho' = atan(0.1 / cos 10 deg) = 5.80 deg > gamma = 4.79 deg: a wheel torque cannot drive the worm; it
    creeps (tanh regularisation, Vs ~ v_t) at < 1 % of the frictionless speed reached in the same time."""
    locked = _wheel_torque_worm_free(0.1)
    free = _wheel_torque_worm_free(0.0)
    w_locked = abs(locked.series["worm_speed_rpm"][-1])
    w_free = abs(free.series["worm_speed_rpm"][-1])
    # 100 rpm: bound below the measured frictionless speed; 1e-2: the creep criterion of the docstring
    assert w_free > 100.0
    assert w_locked < 0.01 * w_free


def test_not_self_locking_worm_runs_back():
    """The counter-case: rho' = 1.16 deg < gamma: the same wheel torque back-drives the worm freely."""
    run = _wheel_torque_worm_free(0.02)
    free = _wheel_torque_worm_free(0.0)
    assert abs(run.series["worm_speed_rpm"][-1]) > 0.3 * abs(free.series["worm_speed_rpm"][-1])


def test_speed_driven_wheel_of_self_locking_pair_is_held():
    """A speed-driven wheel of a self-locking pair stalls and the mesh holds (wormsim.physics.locking): the run ends held
    with `locked` true (before: the servo wound the mesh up until the teeth would skip, exit 3)."""
    sc = scen(
        "seat_motor",
        "drive.on=wheel",
        "drive.speed_rpm=0.68",
        "drive.ramp_s=0.05",
        "load.on=worm",
        "load.torque_nm=0.01",
        "contact.friction=0.1",
        "contact.friction_static=null",
        "contact.friction_dynamic=null",
        "simulation.duration_s=0.5",
    )
    s = torsional.simulate(sc).summary
    assert s["locked"] is True and s["holding_torque_nm"] > 0
    # the creep is the friction law's regularisation (sign of the slip over v_t / 10), not the command's: measured
    # 0.265 rpm here and at a 30x faster wheel; its sliding speed stays below contact.transition_velocity_m_s
    # (static friction holds: measured 1.2e-4 m/s against 1e-3 m/s)
    g = derive(sc.gear)
    vs = s["creep_speed_rpm"] * 2 * math.pi / 60 * g.r1 / math.cos(g.gamma)
    assert vs < sc.contact.transition_velocity_m_s


def _ms(name, samples=32):
    sc = scen(name)
    g = derive(sc.gear)
    kp, src = ST.per_length_stiffness(sc.contact, g, sc.materials)
    return g, kp, src, M.compute(g, kp, src, samples)


@pytest.mark.parametrize("name", SEEDS)
def test_mesh_stiffness_periodic_with_the_mesh_cycle(name):
    """k at theta1 + m 2 pi / z1 equals k at theta1 (the pattern of space k moves to space k + 1)."""
    g, kp, src, ms = _ms(name, 16)
    th = ms.theta1_rad[::3]
    k0 = M.stiffness_at(g, kp, th)
    for m in (1, 2, -1):
        np.testing.assert_allclose(M.stiffness_at(g, kp, th + m * ms.period_rad), k0, rtol=1e-9)
    np.testing.assert_allclose(k0, ms.k_theta_fwd_nm_per_rad[::3], rtol=1e-9)


@pytest.mark.parametrize("name", SEEDS)
def test_mesh_stiffness_mean_in_expected_range(name):
    """k_mesh = K (contact line length / b2) weighted by the squared arm ratio: with 2-4 teeth in contact along
    diagonal lines, the mean lies between 1 and 4 pair stiffnesses, and the arm of the flank normal stays within
    10 % of the pitch-point arm r2 cos(a_n) cos(g), so k_mesh / K = (L / b2) (1 +- 0.2)."""
    g, kp, src, ms = _ms(name)
    K_pair = kp * g.face_width
    ratio = ms.k_mesh_fwd_n_per_m.mean() / K_pair
    # 1-4 pair stiffnesses for 2-4 teeth on diagonal contact lines (docstring estimate); teeth 2-5 likewise
    assert 1.0 < ratio < 4.0
    assert ms.k_mesh_fwd_n_per_m.mean() == pytest.approx(K_pair * ms.length_fwd_m.mean() / g.face_width, rel=0.2)
    assert 2 <= ms.teeth_fwd.min() and ms.teeth_fwd.max() <= 5
    # the two flanks of a symmetric tooth give the same stiffness
    assert ms.k_mesh_rev_n_per_m.mean() == pytest.approx(ms.k_mesh_fwd_n_per_m.mean(), rel=0.02)
    assert np.all(ms.k_mesh_fwd_n_per_m > 0)
    if name == "involute_41":  # no stiffness in the file: the teeth's compliance (wormsim.tooth.compliance)
        from wormsim.tooth.stiffness import line_stiffness_n_per_m2

        assert src == "teeth"
        assert kp == pytest.approx(line_stiffness_n_per_m2(g, scen(name).materials), rel=1e-12)
        assert kp < math.pi * effective_modulus_pa(scen(name).materials) / 4 / 2  # softer than Hertz's rigid teeth


@pytest.mark.parametrize("mode", [("contact.friction=0.07",), ("contact.friction_group=II",), ()])
def test_fast_friction_matches_contact_module(mode):
    overrides = (("contact.friction_static=null", "contact.friction_dynamic=null") if mode else ()) + mode
    sc = scen("seat_motor", *overrides)
    mu = friction_coefficient_scalar(sc.contact)
    vs = np.array([0.0, 2e-4, 7e-4, 1e-3, 0.01, 0.5, 3.0])
    np.testing.assert_allclose([mu(v) for v in vs], friction_coefficient(sc.contact, vs), rtol=1e-12)


def test_backward_euler_agrees_with_error_controlled_lsoda():
    """The fixed-step implicit scheme (default) against scipy LSODA (rtol 1e-7) on the screw jack."""
    sc = scen("screw_jack", "simulation.duration_s=0.15")
    a = torsional.simulate(sc).summary
    b = torsional.simulate(sc, method="LSODA").summary
    for k in ("tangential_force_mean_n", "efficiency", "ratio", "worm_torque_mean_nm", "radial_force_mean_n"):
        assert a[k] == pytest.approx(b[k], rel=5e-3), k


@pytest.mark.parametrize(
    "overrides",
    [
        ("gear.hand=left",),
        ("gear.profile=ZA",),
        ("gear.worm_starts=2", "gear.wheel_teeth=40"),
        ("drive.speed_rpm=-1330",),
    ],
)
def test_variants_hand_profile_starts_direction(overrides):
    """Left hand, ZA profile, two starts, reverse drive: closed forms hold and the wheel turns as INTERFACE.md says
    (positive worm rotation drives the wheel positive for a right-hand worm, negative for a left-hand one)."""
    sc = scen("screw_jack", *overrides)
    r = torsional.simulate(sc)
    s, g = r.summary, derive(sc.gear)
    assert abs(s["ratio"] / g.ratio - 1) < 1e-3
    assert abs(s["tangential_force_mean_n"] * g.r2 / sc.load.torque_nm - 1) < 0.02
    assert abs(s["efficiency"] / (math.tan(g.gamma) / math.tan(g.gamma + rho_prime(s, g))) - 1) < 0.03
    # 0.5 % of z1 n1 / 60 (seed 001), the meshing line refined on the continuous spectrum (wormsim.results.metrics.mesh_line)
    assert abs(s["mesh_frequency_hz"] / s["mesh_frequency_theory_hz"] - 1) <= 0.005, (
        s["mesh_frequency_hz"],
        s["mesh_frequency_theory_hz"],
    )
    w1, w2 = r.series["worm_speed_rpm"][-1], r.series["wheel_speed_rpm"][-1]
    assert np.sign(w1) == np.sign(sc.drive.speed_rpm)
    assert np.sign(w2) == np.sign(w1) * g.hand


def test_driven_machine_inertia_adds_to_the_loaded_shaft():
    from wormsim.torsional.dynamics import inertias

    base = load_scenario(ROOT / "scenarios" / "seat_motor.yaml")
    g = derive(base.gear)
    i1, i2 = inertias(base.materials, base.load, g)
    heavy = load_scenario(ROOT / "scenarios" / "seat_motor.yaml", ["load.inertia_kg_m2=2e-4"])
    j1, j2 = inertias(heavy.materials, heavy.load, g)
    # the load.inertia_kg_m2=2e-4 input adds to the loaded shaft only
    assert j1 == i1 and abs(j2 - i2 - 2e-4) < 1e-15
    on_worm = load_scenario(
        ROOT / "scenarios" / "seat_motor.yaml", ["load.inertia_kg_m2=2e-4", "load.on=worm", "drive.on=wheel"]
    )
    k1, k2 = inertias(on_worm.materials, on_worm.load, g)
    assert k2 == i2 and abs(k1 - i1 - 2e-4) < 1e-15


def test_backward_euler_globalised_newton_lands_in_a_steep_friction_band():
    """A worm speed braked by a tanh friction direction (a1 = B - A tanh(omega1 / v), A h >> v: the band |omega1| < v
    is crossed in one Newton update): entering the band at 0.05 rad/s, the plain Newton iteration cycles between the
    two saturated sides (their Jacobian is flat) at every timestep down to h / 1024 (the screw jack's held back-drive,
    tests/physics/test_locking.py); the backtracking fallback lands on the quasi-static creep v atanh(B / A)."""
    big, held, band = 1e5, 5e4, 1e-3

    def acc(t, th1, w1, th2, w2):
        if t <= 0.0025 + 1e-12:
            return 20.0, -w2
        return held - big * math.tanh(w1 / band), -w2

    t, Y, _ = torsional.integrate_backward_euler(acc, 0.01, 1e-3)
    assert Y[1, 2] == pytest.approx(0.04, rel=1e-12)  # the plain steps before the band, unchanged
    creep = band * math.atanh(held / big)
    assert np.allclose(Y[1, 4:], creep, rtol=1e-6, atol=0.0)
