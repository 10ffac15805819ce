"""Exact-flank contact with assembly errors (issue 12 on issue 13's flanks; wormsim.tooth.pose): the kernel
maps the wheel flanks through the displaced bodies as MuJoCo places them. Checks: with the nominal poses the pose
path gives the nominal kernel's contacts (1e-12), and with each error the kernel's first touch is where the kinematic
TCA (meshgen.kinematic_tca: meshgen.displaced's transforms and meshgen.worm.thread_gap, no MuJoCo) puts it. Loaded
runs: docs/errors.md, "Loaded, exact flanks"."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tests.conftest import SCENARIOS
from wormsim.contact3d.flank_step import FlankContacts
from wormsim.contact3d.mjcf import build_model
from wormsim.scenario import load_scenario
from wormsim.tooth import pose as flank_pose

SEAT = ["contact.geometry=flanks", "simulation.resolution=medium"]


def _built(name: str, sets=()):
    return build_model(load_scenario(SCENARIOS / f"{name}.yaml", SEAT + list(sets)))


def _pose(bm, d, fc, th1, th2):
    d.qpos[fc.qa1], d.qpos[fc.qa2] = th1, th2
    mujoco.mj_kinematics(bm.model, d)


def test_pose_path_with_the_nominal_poses_gives_the_nominal_contacts():
    """Zero errors take the nominal kernel (P without poses); the pose path fed the perfect pair's poses from MuJoCo
    finds the same contacts: positions to 1e-12 m, normals to 1e-12, depths to 1e-12 m, same (tooth, flank, slice)."""
    bm = _built("seat_motor", ["errors.center_distance_mm=0"])
    assert bm.deviations is None
    d = mujoco.MjData(bm.model)
    fc0 = FlankContacts(bm, bm.law.contacts_per_pair)
    assert not fc0.displaced
    fc1 = FlankContacts(bm, bm.law.contacts_per_pair)
    fc1.displaced, fc1._set_pose = True, flank_pose.set_pose
    fc1.params = flank_pose.displaced_params(fc1.grid.params, np.zeros(bm.geometry.z2))
    g = bm.geometry
    total = 0
    for th1 in np.linspace(0.0, 2 * math.pi, 7):
        for s in (-2.0, 0.5, 2.0):  # wheel turned from the conjugate angle by s backlash angles
            _pose(bm, d, fc0, th1, g.hand * th1 * g.z1 / g.z2 + s * g.backlash / (2 * g.r2))
            n = fc0.find(d)
            assert fc1.find(d) == n
            total += n
            for a, b in ((fc0.pos, fc1.pos), (fc0.nrm, fc1.nrm), (fc0.depth, fc1.depth)):
                assert np.abs(a[:n] - b[:n]).max(initial=0.0) < 1e-12
            assert np.array_equal(fc0.meta[:n, :3], fc1.meta[:n, :3])
    assert total > 50


ERRORS = {
    "wheel_axial_offset": ["errors.wheel_axial_offset_mm=0.1"],
    "shaft_angle": ["errors.shaft_angle_deg=0.1"],
    "center_distance": ["errors.center_distance_mm=-0.03"],
    "worm_runout": ["errors.worm_runout_mm=0.01"],
}


@pytest.mark.parametrize("case", list(ERRORS))
def test_kernel_first_touch_is_the_kinematic_tca(case):
    """Seat motor, each error: at sampled worm angles the wheel is turned past the TCA's first touch g_side by E and
    2 E (E = 100 urad); the kernel's deepest contact on that flank grows at the moment arm and extrapolates to zero
    depth at g_side within 1 um of play (r2 x angle). The kernel sees the slice centres only, so it touches a little
    later than the TCA's grid, which reaches the face edges (measured: 0.2 um on side +1, 0.8 um on side -1 with the
    wheel axial offset, whose first touch is on the face edge)."""
    bm = _built("seat_motor", ERRORS[case])
    g, kin = bm.geometry, bm.kinematic_tca
    d = mujoco.MjData(bm.model)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    assert fc.displaced
    E = 1e-4
    idx = np.linspace(0, len(kin.theta1_rad) - 1, 9).astype(int)
    worst = 0.0
    for side, gaps, sg in ((+1, kin.gap_fwd_rad, 0), (-1, kin.gap_rev_rad, 1)):
        for i in idx:
            th1, gk = float(kin.theta1_rad[i]), float(gaps[i])
            th2c = g.hand * th1 * g.z1 / g.z2
            dep = []
            for e in (E, 2 * E):
                _pose(bm, d, fc, th1, th2c - g.hand * side * (gk + e))
                n = fc.find(d)
                on = fc.meta[:n, 1] == sg
                assert on.any(), (case, side, th1)
                dep.append(float(fc.depth[:n][on].max()))
            arm = (dep[1] - dep[0]) / E
            assert arm == pytest.approx(g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma), rel=0.1)
            g0 = gk + E - dep[0] / arm
            worst = max(worst, abs(g0 - gk) * g.r2)
    assert worst < 1e-6, worst


def test_a_shifted_tooth_meshes_as_the_tooth_turned_by_its_pitch_deviation():
    """Pitch deviation f_k (the per-tooth angle in P): tooth k's contacts at wheel angle theta2 are the unshifted
    tooth's at theta2 + f_k / r2 (to 1e-12), and the other teeth's are unchanged. (The wheel runout is the worm
    runout's mechanism on the other hinge, checked with the TCA above.)"""
    bm = _built("seat_motor")
    g = bm.geometry
    d = mujoco.MjData(bm.model)
    fc0 = FlankContacts(bm, bm.law.contacts_per_pair)
    fc1 = FlankContacts(bm, bm.law.contacts_per_pair)
    fc1.displaced, fc1._set_pose = True, flank_pose.set_pose
    bl = g.backlash / (2 * g.r2)
    th1 = 0.7
    th2 = g.hand * th1 * g.z1 / g.z2 - 2.0 * bl
    _pose(bm, d, fc0, th1, th2)
    fc0.find(d)
    ks = fc0.window(th2).copy()
    f = 8e-6
    checked = 0
    for k in ks:
        shift = np.zeros(g.z2)
        shift[int(k) % g.z2] = f / g.r2
        fc1.params = flank_pose.displaced_params(fc1.grid.params, shift)
        _pose(bm, d, fc0, th1, th2)
        n1 = fc1.find(d)
        got = {tuple(fc1.meta[i, :3].astype(int)): fc1.depth[i] for i in range(n1)}
        base = {tuple(fc0.meta[i, :3].astype(int)): fc0.depth[i] for i in range(fc0.find(d))}
        _pose(bm, d, fc0, th1, th2 + f / g.r2)
        turned = {tuple(fc0.meta[i, :3].astype(int)): fc0.depth[i] for i in range(fc0.find(d))}
        for key in set(got) | set(base) | set(turned):
            want = turned if key[0] == k else base
            assert key in got and key in want, key
            assert got[key] == pytest.approx(want[key], abs=1e-12)
        checked += sum(key[0] == k for key in got)
    assert checked >= 8


# ----------------------------------------------------------------------------- loaded runs (contact3d, exact flanks)

# seat motor at 4 N m: its mesh approach (max penetration, measured 5.7 um) is about the kinematic TCA's marking film
# (6 um), so the loaded pattern is comparable with the kinematic one; short and coarse for CI (3600 rpm: 60 Hz mesh)
LIGHT = [
    "contact.geometry=flanks",
    "drive.speed_rpm=3600",
    "drive.ramp_s=0.01",
    "load.ramp_s=0.01",
    "simulation.duration_s=0.06",
    "simulation.resolution=coarse",
    "load.torque_nm=4",
]
# screw jack at its own speed and load, short and coarse
JACK = [
    "contact.geometry=flanks",
    "drive.ramp_s=0.02",
    "load.ramp_s=0.02",
    "simulation.duration_s=0.1",
    "simulation.resolution=coarse",
]
_RUNS: dict = {}


def _run(name: str, sets: tuple):
    if (name, sets) not in _RUNS:
        from wormsim.contact3d.runner import simulate

        sc = load_scenario(SCENARIOS / f"{name}.yaml", list(sets))
        _RUNS[name, sets] = (sc, simulate(sc))
    return _RUNS[name, sets]


def _kinematic_centroid_m(sc, res) -> float:
    """The kinematic TCA's film pattern centroid on the working flank (meshgen.kinematic_tca; zero errors: analysed
    here)."""
    from meshgen import displaced
    from meshgen import kinematic_tca as kt
    from wormsim.physics import gear_theory as gt

    bm = res.extra["built"]
    g = bm.geometry
    kin = bm.kinematic_tca if bm.kinematic_tca is not None else kt.analyse(g, displaced.Deviations())
    pat = kin.pattern_fwd if gt.duty(sc, g.hand).working_flank > 0 else kin.pattern_rev
    return float(pat["centroid_face_m"])


def test_wheel_axial_offset_moves_the_loaded_pattern_as_the_kinematic_tca():
    """Seat motor, wheel axial offset +-0.1 mm at the film-equivalent load: the loaded pattern (contact normal
    force-weighted centroid over the steady window) moves across the face opposite to the offset (the wheel moved +z
    meets the worm with its -zeta edge, docs/errors.md), by 0.6-1.0 of the kinematic TCA's shift (measured 0.76 and
    0.69: -1.25 / +1.41 mm against -1.65 / +2.05 mm; the load spreads the band beyond the film), the two signs within
    25 % of each other, and the band narrows (95 % extent 2.8-2.9 mm against 4.7 mm)."""
    sc0, r0 = _run("seat_motor", tuple(LIGHT))
    s0 = r0.summary
    # 6.0 um: the kinematic TCA's marking film (meshgen.kinematic_tca, LIGHT's comment above); measured 5.7 um
    assert 0.5 < s0["max_penetration_um"] / 6.0 < 1.5
    c0, k0 = s0["contact_pattern_centroid_face_mm"], _kinematic_centroid_m(sc0, r0)
    shifts = {}
    for dz in (0.1, -0.1):
        sc, r = _run("seat_motor", tuple(LIGHT + [f"errors.wheel_axial_offset_mm={dz}"]))
        s = r.summary
        shift = s["contact_pattern_centroid_face_mm"] - c0
        kin = (_kinematic_centroid_m(sc, r) - k0) * 1e3
        assert np.sign(shift) == np.sign(kin) == -np.sign(dz)
        # 0.6-1.0: bounds around the measured 0.76 / 0.69 of this code (docstring; no independent source for the ratio)
        assert 0.6 < shift / kin < 1.0, (dz, shift, kin)
        assert s["contact_pattern_extent_face_mm"] < 0.7 * s0["contact_pattern_extent_face_mm"]
        shifts[dz] = shift
    assert abs(shifts[0.1]) == pytest.approx(abs(shifts[-0.1]), rel=0.25)


def test_shaft_angle_moves_the_pattern_along_the_face_and_raises_the_peak_pressure():
    """Screw jack, shaft angle +0.1 deg at its working load: the loaded pattern moves along the face as the kinematic
    TCA's (measured -8.93 mm against -8.69 mm; 10 % asserted) and narrows (95 % extent 5.2 mm of 20.3 mm); the peak
    Hertz pressure rises as the line load does, p ~ sqrt(w) with w ~ 1 / extent: measured 715 MPa against 354 MPa
    (x 2.02), sqrt(20.3 / 5.2) = 1.97 (20 % asserted)."""
    sc0, r0 = _run("screw_jack", tuple(JACK))
    sc, r = _run("screw_jack", tuple(JACK + ["errors.shaft_angle_deg=0.1"]))
    s0, s = r0.summary, r.summary
    shift = s["contact_pattern_centroid_face_mm"] - s0["contact_pattern_centroid_face_mm"]
    kin = (_kinematic_centroid_m(sc, r) - _kinematic_centroid_m(sc0, r0)) * 1e3
    assert abs(kin) > 0.2 * s0["contact_pattern_extent_face_mm"]
    assert shift == pytest.approx(kin, rel=0.1)
    narrow = s0["contact_pattern_extent_face_mm"] / s["contact_pattern_extent_face_mm"]
    # narrow > 2 / rise > 1.3: below the measured x 3.9 and x 2.02 of the docstring (this code's runs)
    assert narrow > 2
    rise = s["contact_pressure_max_mpa"] / s0["contact_pressure_max_mpa"]
    assert rise > 1.3
    assert rise == pytest.approx(math.sqrt(narrow), rel=0.2)


@pytest.mark.xfail(
    strict=True,
    reason=(
        "seat motor, shaft angle 0.3 deg at 4 N m (its default step 6.4e-6 s): contact_pressure_max_mpa 274 MPa "
        "against 322 MPa without it (mean 109 against 81 MPa; the averaged peak, wormsim.tooth.hertz (4); with 128 "
        "points along the profile, decision 0060; with 64: 232 against 288 MPa, one contact's p_H 252 against 316 "
        "MPa, at 24 N m 689 against 707 MPa, one contact's 757 against 774 MPa): "
        "without the tilt the maximum sits next to the undercut (face -0.31 mm, rho' 0.18 mm against a median 4.5 mm), "
        "which the tilt unloads (docs/errors.md, sec. 6)"
    ),
)
def test_seat_motor_shaft_angle_raises_the_peak_pressure():
    _, r0 = _run("seat_motor", tuple(LIGHT))
    _, r = _run("seat_motor", tuple(LIGHT + ["errors.shaft_angle_deg=0.3"]))
    assert r.summary["contact_pattern_centroid_face_mm"] < r0.summary["contact_pattern_centroid_face_mm"] - 1.0
    assert r.summary["contact_pressure_mean_mpa"] > 1.2 * r0.summary["contact_pressure_mean_mpa"]
    assert r.summary["contact_pressure_max_mpa"] > r0.summary["contact_pressure_max_mpa"]
