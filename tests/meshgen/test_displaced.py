"""Assembly errors and manufacturing deviations (issue 12): limits, the displaced pair's geometry, the kinematic TCA
(meshgen.kinematic_tca) against a first-order theory on the perfect pair's contact lines, and the torsional level.
Numbers and derivations: docs/errors.md."""

from __future__ import annotations

import math
import subprocess
import sys
import warnings
from pathlib import Path

import contourpy
import numpy as np
import pytest

from meshgen import displaced
from meshgen import kinematic_tca as kt
from meshgen.geometry import GeometryError, derive
from wormsim.physics.geometry import displaced_pair
from wormsim.scenario import ScenarioError, load_scenario
from wormsim.tooth import mesh_stiffness as msk

SCEN = Path(__file__).resolve().parents[2] / "scenarios"
warnings.filterwarnings("ignore", category=RuntimeWarning)


def _gear(name: str, sets=()):
    sc = load_scenario(SCEN / f"{name}.yaml", list(sets))
    return sc, derive(sc.gear)


def _tca(name: str, sets=(), **kw):
    sc, g = _gear(name, sets)
    return g, kt.analyse(g, displaced.check_limits(g, sc.errors), **kw)


def line_theory(g, th1s, side, disp):
    """First-order theory (docs/errors.md (9)): a small rigid displacement u(p) of the wheel relative to the worm
    changes the clearance of flank `side` at a contact point p by side u . n / arm (wheel angle; n the flank normal
    oriented so that the wheel's rotation opens side +1, arm = |(e_z x p) . n|); the flank first touches where the
    change is least, on the PERFECT pair's contact lines at theta1 (wormsim.tooth.mesh_stiffness's field and
    lines, independent of the displaced-flank TCA). disp(theta1, P) -> (n, 3). Returns the change of g_side."""
    fld = msk._flank_field(g, side)
    gen = contourpy.contour_generator(z=fld.c, name="serial", corner_mask=True)
    nrm = np.cross(np.gradient(fld.xyz, axis=0), np.gradient(fld.xyz, axis=1))
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    pitch2 = 2 * math.pi / g.z2
    out = np.zeros(len(th1s))
    for m, th1 in enumerate(th1s):
        th2 = g.hand * th1 * g.z1 / g.z2
        best = np.inf
        for k in range(math.ceil((fld.c.min() - th2) / pitch2), math.floor((fld.c.max() - th2) / pitch2) + 1):
            ang = th2 + k * pitch2
            R = np.array([[math.cos(ang), -math.sin(ang), 0], [math.sin(ang), math.cos(ang), 0], [0, 0, 1]])
            for ln in gen.lines(ang):
                if len(ln) < 2:
                    continue
                P = msk._bilinear(fld.xyz, ln[:, 1], ln[:, 0]) @ R.T
                N = msk._bilinear(nrm, ln[:, 1], ln[:, 0]) @ R.T
                tn = -P[:, 1] * N[:, 0] + P[:, 0] * N[:, 1]
                dg = side * np.sum(disp(th1, P) * N * np.sign(tn)[:, None], axis=1) / np.abs(tn)
                best = min(best, float(dg.min()))
        out[m] = best
    return out


# ----------------------------------------------------------------------------- zero errors


def test_zero_errors_take_the_perfect_pairs_path_bit_identically():
    from wormsim.run import simulate

    base = ["model=torsional", "simulation.duration_s=0.1"]
    zeros = [
        f"errors.{k}=0"
        for k in (
            "center_distance_mm",
            "shaft_angle_deg",
            "wheel_axial_offset_mm",
            "worm_axial_offset_mm",
            "wheel_runout_mm",
            "worm_runout_mm",
        )
    ]
    a = simulate(load_scenario(SCEN / "screw_jack.yaml", base))
    b = simulate(
        load_scenario(
            SCEN / "screw_jack.yaml",
            base + zeros + ["errors.wheel_runout_phase_deg=40", "errors.wheel_pitch_deviation_um=[0, 0]"],
        )
    )

    def drop(s):
        return {k: v for k, v in s.items() if "wall" not in k}

    assert drop(a.summary) == drop(b.summary)
    assert "transmission_error_kinematic_p2p_urad" not in a.summary
    for k in a.series:
        assert np.array_equal(a.series[k], b.series[k]), k


def test_displaced_transforms_reduce_to_the_nominal_frames():
    from meshgen import assembly

    _, g = _gear("seat_motor")
    dev = displaced.Deviations()
    for th in (0.0, 0.7, -2.0):
        assert np.array_equal(displaced.worm_to_assembly(g, dev, th), assembly.worm_to_assembly(th, g))
        assert np.array_equal(displaced.wheel_to_assembly(g, dev, th), assembly.wheel_to_assembly(th))


def test_perfect_pair_play_is_the_backlash_and_te_is_flat():
    g, res = _tca("seat_motor")
    # j / 2 per flank: 25 um of the 0.05 mm backlash, from the exact flanks to within the grid refinement (nm)
    assert np.max(np.abs(res.gap_fwd_rad * g.r2 - g.backlash / 2)) < 5e-9
    assert np.max(np.abs(res.play_m(g) - g.backlash)) < 1e-8
    assert np.ptp(res.te_rad(1)) < 0.5e-6  # measured 0.14 urad (grid refinement), against 2149 urad for 20 um runout


def test_worm_axial_offset_is_a_phase_only():
    g, ref = _tca("seat_motor")
    g, res = _tca("seat_motor", ["errors.worm_axial_offset_mm=0.3"])
    assert np.max(np.abs(res.gap_fwd_rad - ref.gap_fwd_rad)) * g.r2 < 1e-8
    assert np.max(np.abs(res.gap_rev_rad - ref.gap_rev_rad)) * g.r2 < 1e-8


# ----------------------------------------------------------------------------- limits (exit 2)


@pytest.mark.parametrize(
    "key,value,words",
    [
        ("center_distance_mm", 0.8, "addendum"),  # (4) h_a = 0.70 mm
        ("center_distance_mm", -0.15, "radial approach"),  # (3) 0.1405 mm (tip clearance)
        ("wheel_runout_mm", 0.15, "radial approach"),
        ("worm_runout_mm", 0.15, "radial approach"),
        ("shaft_angle_deg", 0.6, "asin(j / b2)"),  # (5) 0.573 deg
        ("wheel_axial_offset_mm", 0.4, "throat"),  # (6) 0.357 mm
        ("worm_axial_offset_mm", 1.2, "threaded length"),  # (7) 1.10 mm
        ("wheel_pitch_deviation_um", [0, 26], "flank clearance"),  # (8) 25 um
    ],
)
def test_errors_beyond_their_limit_are_rejected_naming_it(key, value, words):
    sc, g = _gear("seat_motor", [f"errors.{key}={value}"])
    with pytest.raises(GeometryError) as exc:
        displaced.check_limits(g, sc.errors)
    assert f"errors.{key}" in str(exc.value) or "radial approach" in str(exc.value)
    assert words in str(exc.value)


def test_errors_within_each_limit_but_interfering_together_are_rejected():
    # each within its own limit ((3): 0.140 mm, (5): 0.573 deg); together they close the play (measured -25 um)
    sc, g = _gear("seat_motor", ["errors.center_distance_mm=-0.12", "errors.shaft_angle_deg=0.3"])
    dev = displaced.check_limits(g, sc.errors)
    with pytest.raises(GeometryError, match="close the play"):
        kt.check_play(g, kt.analyse(g, dev))
    # the simulator's edge turns it into ScenarioError (exit 2)
    with pytest.raises(ScenarioError, match="close the play"):
        displaced_pair(sc.errors, g)


def test_cli_exit_2_names_the_limit(tmp_path):
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "wormsim",
            "run",
            str(SCEN / "seat_motor.yaml"),
            "--out",
            str(tmp_path / "o"),
            "--set",
            "model=torsional",
            "--set",
            "errors.shaft_angle_deg=1",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 2, p.stderr
    assert "errors.shaft_angle_deg" in p.stderr and "Traceback" not in p.stderr


def test_wedge_rejects_errors():
    with pytest.raises(ScenarioError, match="errors"):
        load_scenario(SCEN / "mov_1.yaml", ["errors.center_distance_mm=0.01"])


# ----------------------------------------------------------------------------- centre distance -> backlash


@pytest.mark.parametrize("da_mm", [0.01, -0.01])
def test_center_distance_changes_the_play_as_the_line_theory_predicts(da_mm):
    g, res = _tca("seat_motor", [f"errors.center_distance_mm={da_mm}"])
    da = da_mm * 1e-3

    def up(th1, P):  # the wheel seen from the worm: +y
        return np.tile([0.0, da, 0.0], (len(P), 1))

    theory = g.r2 * (line_theory(g, res.theta1_rad, 1, up) + line_theory(g, res.theta1_rad, -1, up))
    dj, dj_theory = np.mean(res.play_m(g)) - g.backlash, np.mean(theory)
    # measured: +10 um: TCA +2.20 um, line theory +2.155 um (the opening contact moves to the line ends, which the
    # conjugate field truncates); -10 um: -3.913 / -3.916 um; the pitch-point rack value 2 da tan(alpha_x) = 3.54 um
    assert dj == pytest.approx(dj_theory, rel=0.03)
    rack = 2 * da * math.tan(g.alpha_x)
    assert (abs(dj) < abs(rack)) if da > 0 else (abs(dj) > abs(rack))


# ----------------------------------------------------------------------------- runout


@pytest.fixture(scope="module")
def runout():
    return _tca("screw_jack", ["errors.wheel_runout_mm=0.02"], samples_per_mesh=8)


def test_wheel_runout_gives_te_2e_over_r2_and_the_line_theory_shape(runout):
    g, res = runout
    e = 0.02e-3
    te = res.te_rad(1)
    # rough rule 2 e / r2 = 1333 urad; measured 1398.7 (the radial swing adds e tan(alpha) on the flank)
    assert np.ptp(te) == pytest.approx(2 * e / g.r2, rel=0.06)
    th2 = g.hand * res.theta1_rad * g.z1 / g.z2

    # the pitch circle's centre, turning with the wheel: a translation of the wheel (phase 0)
    def disp(th1, P):
        a = g.hand * th1 * g.z1 / g.z2
        return np.tile([e * math.cos(a), e * math.sin(a), 0.0], (len(P), 1))

    theory = -(g.backlash / (2 * g.r2) + line_theory(g, res.theta1_rad, 1, disp))
    assert np.max(np.abs(te - theory)) < 0.02 * np.ptp(theory), np.max(np.abs(te - theory)) * 1e6
    assert len(th2) == 24 * 8


def test_wheel_runout_gives_sidebands_at_f_mesh_plus_minus_f_wheel(runout):
    g, res = runout
    n = len(res.theta1_rad)  # one wheel revolution: FFT bins are wheel orders
    amp = np.abs(np.fft.rfft(res.te_rad(1))) * 2 / n
    mesh = g.z2  # the mesh frequency is order z2 of the wheel (z1 threads per worm turn)
    background = np.median(amp[3 : n // 2])
    # measured (urad): order 1: 696; 23: 2.64, 24: 3.19, 25: 2.60; background 0.033
    assert amp[mesh - 1] > 30 * background and amp[mesh + 1] > 30 * background
    assert 0.5 < amp[mesh - 1] / amp[mesh + 1] < 2


def test_pitch_deviation_steps_te_while_that_tooth_meshes():
    k, f = 5, 5e-6
    g, res = _tca("screw_jack", [f"errors.wheel_pitch_deviation_um=[0, 0, 0, 0, 0, {-f * 1e6}]"], samples_per_mesh=8)
    te = res.te_rad(1)
    base = -g.backlash / (2 * g.r2)
    raised = te - base > 0.5 * f / g.r2
    # tooth 5 shifted back by 5 um closes its forward flank by 5 um: TE steps by f / r2 = 166.7 urad while it meshes
    assert np.max(te) - base == pytest.approx(f / g.r2, rel=0.01)
    assert np.max(np.abs(te[~raised] - base)) < 0.01 * f / g.r2
    # one contiguous engagement, centred where tooth 5 crosses the line of centres
    idx = np.nonzero(raised)[0]
    assert np.all(np.diff(idx) == 1)
    th2 = g.hand * res.theta1_rad[idx] * g.z1 / g.z2
    from meshgen import wheel

    cross = (-math.pi / 2 - wheel.tooth_angle(g, k)) % (2 * math.pi)
    assert abs(np.mean(th2) - cross) < 2 * math.pi / g.z2
    # the opposite flank does not see a tooth shifted away from it (its neighbours carry): flat
    assert np.ptp(res.te_rad(-1)) < 0.01 * f / g.r2


# ----------------------------------------------------------------------------- contact pattern


def test_wheel_axial_offset_moves_the_pattern_across_the_face_symmetrically():
    g, ref = _tca("seat_motor")
    c0 = ref.pattern_fwd["centroid_face_m"]
    shifts = {}
    for dz in (0.1, -0.1):
        g, res = _tca("seat_motor", [f"errors.wheel_axial_offset_mm={dz}"])
        shifts[dz] = res.pattern_fwd["centroid_face_m"] - c0
        # the wheel moved +z meets the worm with its -zeta side (the closing face edge, docs/errors.md)
        assert np.sign(shifts[dz]) == -np.sign(dz)
        assert res.pattern_fwd["extent_face_m"] < 0.5 * ref.pattern_fwd["extent_face_m"]
    # measured -1.65 / +2.05 mm: within 25 % of each other
    assert abs(shifts[0.1]) == pytest.approx(abs(shifts[-0.1]), rel=0.25)


# ----------------------------------------------------------------------------- torsional with errors


def test_torsional_reports_te_with_runout_and_its_sidebands():
    from wormsim.results.metrics import dominant_frequency
    from wormsim.run import simulate

    sc = load_scenario(
        SCEN / "screw_jack.yaml", ["model=torsional", "simulation.duration_s=7.5", "errors.wheel_runout_mm=0.02"]
    )
    r = simulate(sc)
    s, S = r.summary, r.series
    g = derive(sc.gear)
    # a wheel runout e swings the pitch circle's centre tangentially (TE e sin(theta2) / r2) and radially (on the
    # working flank e cos(theta2) tan(alpha_x) / r2): the kinematic TE p2p lies between the tangential swing alone,
    # 2 e / r2, and both swings added in quadrature, 2 e / (r2 cos alpha_x) (docs/errors.md section 4; measured 1398.7
    # urad between 1333.3 and 1419.7)
    e = sc.errors.wheel_runout_mm * 1e-3
    te_kin = s["transmission_error_kinematic_p2p_urad"] * 1e-6
    assert 2 * e / g.r2 < te_kin < 2 * e / (g.r2 * math.cos(g.alpha_x)), (te_kin, 2 * e / g.r2)
    # loaded TE: the kinematic one plus the mesh deflection's ripple (measured 1402.7 over 1.5 s)
    assert s["transmission_error_p2p_urad"] == pytest.approx(s["transmission_error_kinematic_p2p_urad"], rel=0.03)
    assert 0 < s["backlash_measured_mm"] < g.backlash * 1e3 < s["backlash_measured_max_mm"]
    fm = s["mesh_frequency_theory_hz"]
    fw = fm / g.z2
    t = S["t_s"]
    sl = t > t[-1] - 6 / fw  # the last 6 wheel revolutions: bins of fw / 6
    _, df, f, amp = dominant_frequency(t[sl], S["transmission_error_rad"][sl])

    def near(x):
        return amp[int(np.argmin(np.abs(f - x)))]

    # measured (urad): fm 5.33, fm - fw 2.61, fm + fw 2.57, fm +- fw / 2 (between the lines) 0.002
    between = max(near(fm - fw / 2), near(fm + fw / 2))
    assert near(fm - fw) > 100 * between and near(fm + fw) > 100 * between
    assert near(fm - fw) > 1e-6 and near(fm + fw) > 1e-6


# ----------------------------------------------------------------------------- contact3d


def test_contact3d_hinges_and_teeth_follow_the_displaced_geometry():
    import mujoco

    from wormsim.contact3d.mjcf import build_model
    from wormsim.contact3d.slots import repose_window

    sets = [
        "simulation.resolution=coarse",
        "errors.center_distance_mm=0.02",
        "errors.shaft_angle_deg=0.05",
        "errors.wheel_axial_offset_mm=0.03",
        "errors.wheel_runout_mm=0.01",
        "errors.wheel_runout_phase_deg=30",
        "errors.worm_runout_mm=0.005",
        "errors.worm_axial_offset_mm=0.2",
        "errors.wheel_pitch_deviation_um=[0, 10, -5]",
    ]
    sc = load_scenario(SCEN / "seat_motor.yaml", sets)
    bm = build_model(sc)
    g, dev = bm.geometry, displaced.Deviations.from_data(sc.errors)
    m, d = bm.model, mujoco.MjData(bm.model)
    for th1, th2 in ((0.3, 0.1), (-1.0, 0.5)):
        d.qpos[m.jnt_qposadr[m.dof_jntid[bm.worm_dof]]] = th1
        d.qpos[m.jnt_qposadr[m.dof_jntid[bm.wheel_dof]]] = th2
        mujoco.mj_kinematics(m, d)
        for body, T in (
            (bm.worm_body, displaced.worm_to_assembly(g, dev, th1)),
            (bm.wheel_body, displaced.wheel_to_assembly(g, dev, th2)),
        ):
            assert np.allclose(d.xpos[body], T[:3, 3], atol=1e-15)
            assert np.allclose(d.xmat[body].reshape(3, 3), T[:3, :3], atol=1e-14)
    # tooth k's slot turned by 2 pi k / z2 + f_k / r2
    ks = repose_window(bm, 0.0)
    for k in ks:
        q = m.body_quat[bm.slot_bodies[int(k % bm.window_teeth)]]
        ang = 2 * math.atan2(q[3], q[0])
        want = 2 * math.pi * k / g.z2 + [0, 10e-6, -5e-6, *[0] * g.z2][int(k % g.z2)] / g.r2
        assert math.remainder(ang - want, 2 * math.pi) == pytest.approx(0, abs=1e-12)
    assert bm.kinematic_tca is not None and bm.tooth_shift_rad is not None
