"""Exact-flank contact of contact3d (wormsim.tooth.kernel, flank_step): the kernel's distance is meshgen.worm's closed
form, the rigid conjugate pose touches with the backlash as the only gap, and the MuJoCo model built on flank contacts
shows the specified tooth-pair stiffness (issue 13: within 5 %, as tests/contact3d/test_law.py for pieces)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from meshgen import worm
from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from wormsim.contact3d.mjcf import build_model
from wormsim.scenario import load_scenario
from wormsim.tooth import gap, grid, kernel
from wormsim.tooth.window import window_size, window_teeth_at

SCEN = SCENARIOS


@pytest.mark.parametrize("name,profile", [("seat_motor", "ZI"), ("screw_jack", "ZA"), ("involute_41", "ZI")])
def test_kernel_distance_is_meshgen_thread_gap(name, profile):
    g = derive(load_scenario(SCEN / f"{name}.yaml", [f"gear.profile={profile}"]).gear)
    rng = np.random.default_rng(1)
    n = 400
    r = rng.uniform(g.r_f1, g.r_a1, n)
    phi = rng.uniform(-math.pi, math.pi, n)
    z = rng.uniform(-g.worm_length / 2, g.worm_length / 2, n)
    pts = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    th1 = 0.37
    ref = worm.thread_gap(g, pts, th1)
    P = worm.worm_params(g)
    out = np.zeros(6)
    got = np.array([gap.worm_gap(x, y, zz, th1, P, out) for x, y, zz in pts])
    assert np.allclose(got, ref, rtol=0, atol=1e-12 * g.m_x / 1e-3)
    # the normal, on the flank itself (meshgen.worm.flank_points): along the numerical gradient of the distance
    for side in (+1, -1):
        q = worm.flank_points(g, 0.5 * (g.r_f1 + g.r_a1), 0.3, side)
        R = np.array([[math.cos(th1), math.sin(th1), 0], [-math.sin(th1), math.cos(th1), 0], [0, 0, 1.0]])
        x, y, zz = R.T @ q  # the flank turned with the worm by theta1
        assert abs(gap.worm_gap(x, y, zz, th1, P, out)) < 1e-12
        e = 1e-9
        grad = np.array(
            [
                gap.worm_gap(x + e * (i == 0), y + e * (i == 1), zz + e * (i == 2), th1, P, np.zeros(6))
                - gap.worm_gap(x - e * (i == 0), y - e * (i == 1), zz - e * (i == 2), th1, P, np.zeros(6))
                for i in range(3)
            ]
        ) / (2 * e)
        assert np.allclose(out[:3], grad, atol=1e-5)


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack", "involute_41"])
def test_conjugate_pose_touches_across_the_backlash(name):
    """Wheel turned from the conjugate angle by s times the backlash angle j / (2 r2) (half the backlash per flank):
    no contact for |s| <= 0.95; at |s| = 2 the depth is the backlash angle times the moment arm of the flank normal
    (r2 cos(alpha_n) cos(gamma) at the pitch point; the deepest slice within 5 %), on flank A for a lagging wheel."""
    g = derive(load_scenario(SCEN / f"{name}.yaml").gear)
    fg = grid.flank_grid(g, 16)
    W = window_size(g)
    tooth0 = -math.pi / 2 + math.pi / g.z2
    cap = 2 * W * 16
    pos, nrm, dep, meta = np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros((cap, 4))
    bl = g.backlash / (2 * g.r2)
    arm0 = g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma)
    pitch = 2 * math.pi / g.z2
    for th1 in (0.0, 1.1, 2.5):
        th2c = g.hand * th1 * g.z1 / g.z2
        ks = window_teeth_at(th2c, g.z2, W, tooth0).astype(np.int64)
        for s in (-0.95, 0.95):
            n = kernel.find_contacts(
                (fg.xy, fg.c, fg.c_range, fg.span, fg.zeta),
                ks,
                th1,
                th2c + s * bl,
                kernel.MARGIN_PITCH * pitch + 3 * bl,
                fg.params,
                (pos, nrm, dep, meta, np.zeros((len(dep), 2))),
            )
            assert n == 0, (th1, s, dep[:n].max())
        for s, flank in ((-2.0, 0), (2.0, 1)):
            n = kernel.find_contacts(
                (fg.xy, fg.c, fg.c_range, fg.span, fg.zeta),
                ks,
                th1,
                th2c + g.hand * s * bl,
                kernel.MARGIN_PITCH * pitch + 3 * bl,
                fg.params,
                (pos, nrm, dep, meta, np.zeros((len(dep), 2))),
            )
            assert n >= 8 and np.all(meta[:n, 1] == flank)
            assert dep[:n].max() == pytest.approx(bl * arm0, rel=0.05)


def _settle(bm, d, torque_nm: float, steps: int, fc):
    d.ctrl[bm.drive_actuator] = 0.0
    d.ctrl[bm.load_actuator] = torque_nm
    for _ in range(steps):
        fc.step(bm.model, d)


@pytest.fixture(scope="module")
def static_flanks():
    """Worm held at 0 rpm by its servo, frictionless, wheel torques 21 and 24 N m (tests/contact3d/test_law.py), one
    MuJoCo contact per slice (the per-contact law; the default merges 4 per flank)."""
    from wormsim.contact3d.flank_step import FlankContacts
    from wormsim.contact3d.native import split_forward

    sc = load_scenario(
        SCEN / "seat_motor.yaml",
        [
            "drive.speed_rpm=0",
            "drive.ramp_s=0",
            "load.ramp_s=0",
            "contact.geometry=flanks",
            "contact.flank_contacts=slice",
            "contact.friction=0",
            "contact.friction_static=null",
            "contact.friction_dynamic=null",
        ],
    )
    bm = build_model(sc)
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    split_forward(m, d, fc.add)
    out = []
    for T in (21.0, 24.0):
        _settle(bm, d, -T, 6000, fc)
        rel = d.qpos[fc.qa2] - bm.direction * d.qpos[fc.qa1] / bm.geometry.ratio
        C = []
        for i in range(d.ncon):
            c = d.contact[i]
            n = np.array(c.frame[:3])
            w = float(c.solref[0] / bm.law.solref[0])  # the contact's share of its slice (slice_weights)
            C.append((float(d.efc_force[c.efc_address]), -float(c.dist), c.pos[0] * n[1] - c.pos[1] * n[0], w))
        out.append((T, float(rel), np.array(C), float(np.abs(d.qvel).max())))
    return bm, out


def test_flank_contact_stiffness_is_k_over_slices(static_flanks):
    bm, out = static_flanks
    C = out[-1][2]
    assert bm.law.contacts_per_pair == 32  # the seat motor's default slices (flanks.default_slices)
    assert len(C) >= 8
    assert np.all((C[:, 3] > 0) & (C[:, 3] <= 1)) and np.sum(C[:, 3] == 1) >= 8
    ratio = C[:, 0] / C[:, 1] / (C[:, 3] * bm.law.contact_stiffness_n_per_m)
    assert np.all(np.abs(ratio - 1) < 0.05), ratio


def test_flank_static_mesh_stiffness_per_pair_within_5_percent(static_flanks):
    bm, out = static_flanks
    (Ta, tha, Ca, _), (Tb, thb, Cb, vmax) = out
    assert vmax < 1e-3
    k_theta = (Tb - Ta) / abs(thb - tha)
    arm2 = 0.5 * sum(np.sum(C[C[:, 0] > 1e-3, 3] * C[C[:, 0] > 1e-3, 2] ** 2) for C in (Ca, Cb))
    k_pair = k_theta * bm.law.contacts_per_pair / arm2
    print(
        f"flank tooth-pair stiffness {k_pair:.6g} N/m against K = {bm.law.pair_stiffness_n_per_m:.6g} ({len(Cb)} contacts)"
    )
    assert k_pair == pytest.approx(bm.law.pair_stiffness_n_per_m, rel=0.05)


def _exit_sweep(slices: int, samples: int) -> tuple[np.ndarray, np.ndarray]:
    """involute_41's tooth 0 (flank A) through its exit: the rigid conjugate pose held back by the backlash angle and
    10 um of approach, the worm turned over 0.62-0.75 of a mesh cycle (where tooth 0's contact line shrinks to a
    point and leaves); per sample each slice's weight (kernel.slice_weights, find_packed) and the tooth's
    quasi-static load sum w delta / S (in m, per unit of the tooth pair's stiffness K)."""
    g = derive(load_scenario(SCEN / "involute_41.yaml").gear)
    W = window_size(g)
    pitch = 2 * math.pi / g.z2
    tooth0 = -math.pi / 2 + math.pi / g.z2
    bl = g.backlash / (2 * g.r2)
    lag = bl + 10e-6 / (g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma))
    margin = kernel.MARGIN_PITCH * pitch + bl
    fg = grid.flank_grid(g, slices)
    pk = kernel.PackedKernel(fg, fg.params, 2 * W * slices, W, g.z2)
    w = np.zeros((samples, slices))
    load = np.zeros(samples)
    for i, th1 in enumerate(np.linspace(0.62, 0.75, samples) * 2 * math.pi / g.z1):
        th2 = g.hand * (th1 * g.z1 / g.z2 - lag)  # flank A loaded (test_conjugate_pose_touches_across_the_backlash)
        pk.ks[:] = window_teeth_at(th2, g.z2, W, tooth0)
        n = kernel.find_packed(pk.fb, pk.ib, th1, th2, margin, kernel.TAPER_SHARE * margin)
        mine = (pk.meta[:n, 0] == 0) & (pk.meta[:n, 1] == 0)
        w[i, pk.meta[:n, 2][mine].astype(int)] = pk.weight[:n][mine]
        load[i] = np.sum((pk.weight[:n] * pk.depth[:n])[mine]) / slices
    return w, load


def test_slice_weights_follow_the_contact_line_end():
    """The covered share (kernel._line_share) follows the contact line along the flank: where one line end sweeps
    across the face, a slice's weight falls from 1 to 0 while the end crosses it, so its fall starts where its
    neighbour's ends (the falls tile the sweep, within 3 samples of 2000: the weights sum to the covered length;
    not the last slice, where both ends meet).
    With the excess's change across the face at a fixed profile point (the slope before) each fell in 0.45 of the
    time between two slices' exits on this tooth, a staircase in the tooth's load at the slices' exit rate (1.1 kHz
    at 24 slices, beside involute_41's 941 Hz contact mode; docs/contact3d.md, "Default slice count"). No weight
    steps by more than 0.15 per sample (the last slice, as the line shrinks to a point, falls as the square root
    of the time left)."""
    w, _ = _exit_sweep(24, 2000)
    assert np.abs(np.diff(w, axis=0)).max() < 0.15
    ramps = {}
    for j in range(w.shape[1]):
        full = np.nonzero(w[:, j] >= 1.0)[0]
        if len(full) and full[-1] < len(w) - 1 and np.any(w[full[-1] :, j] == 0):
            end = full[-1] + int(np.argmax(w[full[-1] :, j] == 0))
            ramps[j] = (full[-1], end)  # its last sample at 1 and its first at 0 after it
    last = max(ramps, key=lambda j: ramps[j][1])  # the line's last point: both its ends meet in this slice
    pairs = [
        (a, b) for a, b in zip(sorted(ramps), sorted(ramps)[1:], strict=False) if b == a + 1 and last not in (a, b)
    ]
    for a, b in pairs:
        first, second = sorted((ramps[a], ramps[b]))
        assert abs(second[0] - first[1]) <= 3, (a, b, ramps[a], ramps[b])
    assert len(pairs) >= 4, ramps


def test_leaving_tooth_load_converges_in_slices():
    """The leaving tooth's quasi-static load (_exit_sweep) at 24 slices within 1 % of its largest load of 96
    slices' at every sample through its exit, the exit's last sample included (the covered length's square-root
    fall as the line shrinks to a point). Before the weights followed the line (the face slope): 4.5 % at the exit's
    end, where 24 slices' tail lasted 16 samples of 1000 per mesh cycle longer than 192 slices' (docs/contact3d.md,
    "Default slice count")."""
    _, a = _exit_sweep(24, 400)
    _, b = _exit_sweep(96, 400)
    assert b[0] > 0 and b[-1] == 0  # the sweep holds the exit
    assert np.abs(a - b).max() < 0.01 * b.max(), np.abs(a - b).max() / b.max()


APPROACH_M = 1e-6  # mesh_sweep's approach beyond the backlash (the depth of a conjugate contact)


def mesh_sweep(g, slices: int, samples: int, approach_m: float = APPROACH_M) -> dict:
    """The rigid conjugate pose held back by the backlash angle and approach_m, the worm turned over one mesh cycle
    at `samples` points: per window tooth (its unwrapped index) its loaded flank's sum of w delta / S / approach_m
    (its share of the tooth pair's stiffness K) at each sample ("loads"), their sum k(theta) / K ("k_mesh") and the
    worm angles ("th1"). studies/slice_quasi_static.py compares the counts with it."""
    from meshgen import wheel

    W = window_size(g)
    pitch = 2 * math.pi / g.z2
    tooth0 = wheel.tooth_angle(g, 0)
    bl = g.backlash / (2 * g.r2)
    lag = bl + approach_m / (g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma))
    margin = kernel.MARGIN_PITCH * pitch + bl
    fg = grid.flank_grid(g, slices)
    pk = kernel.PackedKernel(fg, fg.params, 2 * W * slices, W, g.z2)
    th1s = np.arange(samples) / samples * 2 * math.pi / g.z1
    loads: dict[int, np.ndarray] = {}
    for i, th1 in enumerate(th1s):
        th2 = g.hand * (th1 * g.z1 / g.z2 - lag)  # flank A loaded (test_conjugate_pose_touches_across_the_backlash)
        pk.ks[:] = window_teeth_at(th2, g.z2, W, tooth0)
        n = kernel.find_packed(pk.fb, pk.ib, th1, th2, margin, kernel.TAPER_SHARE * margin)
        wd = pk.weight[:n] * pk.depth[:n]
        for k in set(pk.meta[:n, 0].astype(int)):
            m = pk.meta[:n, 0] == k
            loads.setdefault(k, np.zeros(samples))[i] = np.sum(wd[m]) / slices / approach_m
    return {"th1": th1s, "loads": loads, "k_mesh": np.sum(list(loads.values()), axis=0)}


def _sweep_dev(name: str, slices: int, samples: int, ref_slices: int = 64) -> tuple[float, float]:
    """mesh_sweep at `slices` against `ref_slices` on the seed: the mesh stiffness's largest difference (share of its
    mean) and each tooth's load's (share of its largest)."""
    g = derive(load_scenario(SCEN / f"{name}.yaml").gear)
    a, b = mesh_sweep(g, slices, samples), mesh_sweep(g, ref_slices, samples)
    k_dev = float(np.abs(a["k_mesh"] - b["k_mesh"]).max() / b["k_mesh"].mean())
    la, lb = a["loads"], b["loads"]
    tooth_dev = max(float(np.abs(la[k] - lb[k]).max() / lb[k].max()) for k in lb if k in la and lb[k].max() > 0)
    return k_dev, tooth_dev


def test_mesh_stiffness_converges_where_the_line_leaves_the_profile():
    """The screw jack's quasi-static mesh stiffness over a mesh cycle (mesh_sweep) at 16 slices (the fluctuation rule's count, below the default's floor of 32) within
    2.5 % of its mean of 64 slices'. Its contact lines leave the wheel's active profile inside the face: the
    entering tooth's at the tip edge, the others' past the profile's lower end (the worm tip's reach). With the
    profile end's gap as the slice's depth at its centre (before decision 0052) each slice carried its centre's depth
    across its width, while that gap falls from the line's depth to zero within a small share of a slice: 3.80 %
    (the entering tooth's load 5.1 % of its largest off 64 slices'); with the depth averaged across the slice
    (kernel._tip_depth) and the line's own depth past the lower end: 1.64 % (32 slices: 1.59 % before, 0.66 %); with
    128 points along the profile (decision 0060) 1.59 %, the entering tooth's load 2.50 % as with 64."""
    k_dev, _ = _sweep_dev("screw_jack", 16, 512)
    assert k_dev < 0.025, k_dev


@pytest.mark.xfail(
    strict=True,
    reason="the screw jack's entering tooth at 16 slices (below the default's floor of 32): its quasi-static load 2.50 % of its "
    "largest off 64 slices' (5.1 % before decision 0052, which averages the depth across a slice where the line "
    "runs off the wheel's tip edge): its line appears on the tip edge at the edge's corners (the throat meets the "
    "outside diameter, 4.8 mm either side of the mid-plane), where how far the line lies past the edge has a kink "
    "across the face (96 -> 154 -> 359 um over three of 64 slices), which the quadratic across a coarse slice does "
    "not follow (docs/decisions/0052-slice-depth-where-the-line-leaves-"
    "the-profile.md)",
)
def test_entering_tooth_load_converges_in_slices():
    """Each window tooth's quasi-static load over a mesh cycle at the screw jack's fluctuation rule's count (16, below
    the default's floor of 32) within 1 % of its largest of 64 slices' (the leaving tooth's exit on involute_41:
    test_leaving_tooth_load_converges_in_slices)."""
    _, tooth_dev = _sweep_dev("screw_jack", 16, 512)
    assert tooth_dev < 0.01, tooth_dev


def trimmed(fg: grid.FlankGrid, points: dict[tuple[int, int], list[int]]) -> grid.FlankGrid:
    """fg with the profile points {(flank, slice): [indices]} trimmed (nan, as wormsim.tooth.trim leaves a point that
    the worm cuts), the slices' spans and conjugate ranges taken again (grid._flank_grid's)."""
    import dataclasses

    psi, c, xy = fg.psi.copy(), fg.c.copy(), fg.xy.copy()
    for (sg, j), idx in points.items():
        psi[sg, j, idx], c[sg, j, idx], xy[sg, j, idx] = np.nan, np.nan, np.nan
    fin = np.isfinite(c)
    rng = np.stack([np.where(fin, c, np.inf).min(axis=2), np.where(fin, c, -np.inf).max(axis=2)], axis=-1)
    n = c.shape[2]
    first = np.where(fin.any(axis=2), np.argmax(fin, axis=2), -1)
    last = np.where(fin.any(axis=2), n - 1 - np.argmax(fin[:, :, ::-1], axis=2), -1)
    span = np.stack([first, last], axis=-1).astype(np.int64)
    return dataclasses.replace(fg, psi=psi, c=c, xy=xy, c_range=rng, span=span)


# the trimmed points of two grids before meshgen's envelope maximum was safeguarded (meshgen.wheel._newton_max): its
# Newton iteration ended up to 36 um below the maximum near the wheel tip at gamma 33.7 deg, and the trim cut those
# points; the grids have none now, the kernel's guards for trimmed points are tested on these (profile indices of a
# 64-point profile: the tests take that grid, TRIMMED_PROFILE)
TRIMMED_PROFILE = 64
STEEP_TRIMMED = {
    (0, 18): [58, 63],
    (0, 19): [47, 50, 51, 53, 54, 55, 58, 59, 60, 61, 63],
    (0, 20): list(range(41, 64)),
    (0, 21): [39, 40, 41, 42],
    (0, 22): [38],
    (0, 24): [37],
    (1, 15): [37],
    (1, 17): [38],
    (1, 18): [39, 40, 41, 42],
    (1, 19): list(range(41, 64)),
    (1, 20): [47, 50, 51, 53, 54, 55, 58, 59, 60, 61, 63],
    (1, 21): [58, 63],
}
Q6_TRIMMED = {
    (1, 66): [61],
    (1, 67): [61, 62],
    (1, 68): [58, 61, 62, 63],
    (1, 69): [58, 59, 61, 62, 63],
    (1, 70): [58, 59, 61, 62, 63],
    (1, 71): [56, 58, 59, 60, 61, 62, 63],
    (1, 72): [56, 57, 58, 59, 60, 61, 62, 63],
}


def test_depths_finite_where_a_trimmed_point_ends_the_profile(monkeypatch):
    """The steep random gear (tests/contact3d/test_random_forces.py STEEP, gamma 33.7 deg, alpha_n 10 deg) at its
    medium count (40) with STEEP_TRIMMED's points trimmed: each tooth's quasi-static share of K over a mesh cycle is
    finite and at most 1 (+2 %). The grid then has trimmed points next to the active profile's last point, where the
    end segment's length is not finite: the slice's depth then stays the line's (kernel._write_contact); without that
    guard the tip-edge depth was NaN and MuJoCo diverged at the first step."""
    from tests.contact3d.test_random_forces import STEEP, _scenario

    g = derive(_scenario(STEEP).gear)
    fg = trimmed(grid.flank_grid(g, 40, TRIMMED_PROFILE), STEEP_TRIMMED)
    monkeypatch.setattr(grid, "flank_grid", lambda g_, s_: fg)
    r = mesh_sweep(g, 40, 256)
    assert np.all(np.isfinite(r["k_mesh"]))
    assert max(float(v.max()) for v in r["loads"].values()) < 1.02


def test_weights_finite_where_the_line_runs_past_a_trimmed_profile_end():
    """left-q6-4start (tests/contact3d/test_variety.py) at 128 slices with Q6_TRIMMED's points trimmed, flank 1 of
    its tooth 1: slice 68's contact
    line runs past its active profile's last point (index 60; point 61 is trimmed, NaN) and neither neighbour has an
    active segment there, so its share comes from the change across the face at the line's point (_face_slope). That
    point is the line's, extrapolated along the end segment; read at the grid points around its fractional index
    (60 and the trimmed 61) the share was NaN and MuJoCo diverged at t = 5.9 ms. Every output is finite at the
    poses where that slice carries."""
    from meshgen import wheel
    from tests.contact3d.test_variety import FLANK_GEARS
    from tests.contact3d.test_variety import GEAR as OTHER

    g = derive(load_scenario(OTHER, FLANK_GEARS["left-q6-4start"]).gear)
    S = 128
    W = window_size(g)
    bl = g.backlash / (2 * g.r2)
    margin = kernel.MARGIN_PITCH * 2 * math.pi / g.z2 + bl
    lag = bl + 1e-6 / (g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma))
    fg = trimmed(grid.flank_grid(g, S, TRIMMED_PROFILE), Q6_TRIMMED)
    assert fg.span[1, 68, 1] == 60
    pk = kernel.PackedKernel(fg, fg.params, 2 * W * S, W, g.z2, S // 4)
    carried = 0
    for th1 in np.linspace(0.5553, 0.5600, 4):
        th2 = g.hand * (th1 * g.z1 / g.z2 - lag)
        pk.ks[:] = window_teeth_at(th2, g.z2, W, wheel.tooth_angle(g, 0))
        n = kernel.find_packed(pk.fb, pk.ib, th1, th2, margin, kernel.TAPER_SHARE * margin)
        nm = int(pk.ib[7])
        for a in (pk.pos[:n], pk.nrm[:n], pk.depth[:n], pk.weight[:n], pk.line[:n], pk.mdepth[:nm], pk.mweight[:nm]):
            assert np.all(np.isfinite(a))
        carried += int(np.any((pk.meta[:n, 1] == 1) & (pk.meta[:n, 2] == 68)))
    assert carried == 4
