"""The exact-flank kernel's open-slice memo (wormsim.tooth.kernel.find_contacts, memo = flank_memo): the contacts
with the memo are the contacts without it, bit for bit, over a mesh cycle of states in sequence: the wheel loaded
with a varying transmission error, at mid-backlash, and jumping between the two (docs/contact3d.md, "Exact flanks:
cost")."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from wormsim.scenario import load_scenario
from wormsim.tooth import grid, kernel
from wormsim.tooth.window import window_size, window_teeth_at


def _setup(name: str, S: int = 16):
    """The seed's gear, S, its flank grid at S slices, the window's teeth W, the first tooth's angle, the kernel's
    margin and the contact buffers' capacity."""
    g = derive(load_scenario(SCENARIOS / f"{name}.yaml").gear)
    W = window_size(g)
    margin = kernel.MARGIN_PITCH * 2 * math.pi / g.z2 + g.backlash / (2 * g.r2)
    return g, S, grid.flank_grid(g, S), W, -math.pi / 2 + math.pi / g.z2, margin, 2 * W * S


def _states(g, steps: int) -> np.ndarray:
    """(theta1, theta2) over one mesh cycle: the wheel turned from the conjugate angle by s backlash angles j / (2 r2),
    s = 1.3 +- 0.2 (flank A loaded, the TE varying), then 0 (mid-backlash, open), then jumps between them."""
    bl = g.backlash / (2 * g.r2)
    th1 = np.linspace(0.3, 0.3 + 2 * math.pi / g.z1, steps)
    t = np.arange(steps)
    s = np.where(t < steps // 2, 1.3 + 0.2 * np.sin(2 * math.pi * 5 * t / steps), 0.0)
    s = np.where((t > 3 * steps // 4) & (t % 40 < 20), 1.5, s)  # closing at once from open
    return np.stack([th1, g.hand * th1 * g.z1 / g.z2 + g.hand * s * bl], axis=1)


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor"])
def test_memo_gives_the_same_contacts(name):
    """find_contacts with and without its memo, and find_packed (memo, slice_weights and frames in one call on
    PackedKernel's buffers) against find_contacts without memo + slice_weights + contact_frames."""
    g, S, fg, W, tooth0, margin, cap = _setup(name)
    memo = kernel.flank_memo(fg, g.z2)
    pk = kernel.PackedKernel(fg, fg.params, cap, W, g.z2)
    runs: dict = {"memo": [], "none": [], "packed": []}
    for use in ("memo", "none"):
        bufs = [np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros((cap, 4)), np.zeros((cap, 2))]
        wf = [np.zeros(cap), np.zeros((cap, 9))]
        for th1, th2 in _states(g, 600):
            ks = window_teeth_at(th2, g.z2, W, tooth0).astype(np.int64)
            args = ((fg.xy, fg.c, fg.c_range, fg.span, fg.zeta), ks, th1, th2, margin, fg.params, tuple(bufs), 0.0)
            n = kernel.find_contacts(*args, memo if use == "memo" else None)
            runs[use].append([b[:n].copy() for b in bufs])
            if use == "none":
                pos, nrm, dep, meta, line = bufs
                n = kernel.slice_weights(meta, line, n, S, pos, nrm, dep, wf[0])
                kernel.contact_frames(nrm, n, wf[1])
                runs["weights"] = runs.get("weights", []) + [[b[:n].copy() for b in bufs + wf]]
                pk.ks[:] = ks
                m = kernel.find_packed(pk.fb, pk.ib, th1, th2, margin, 0.0)
                runs["packed"].append([b[:m].copy() for b in (pk.pos, pk.nrm, pk.depth, pk.meta, pk.line)])
                runs["packed"][-1] += [pk.weight[:m].copy(), pk.frame[:m].copy()]
    loaded = sum(len(a[2]) > 0 for a in runs["none"])
    assert loaded > 250  # the loaded half and the jumps touch
    for x, y in ((runs["memo"], runs["none"]), (runs["packed"], runs["weights"])):
        for a, b in zip(x, y):
            assert len(a[2]) == len(b[2])
            for u, v in zip(a, b):
                assert np.array_equal(u, v)
    # the memo was used: open slices remembered at the end of the sequence (mid-backlash stretch and jumps)
    for table in (memo[0], pk.memo):
        assert np.count_nonzero(table[..., 0] > 0) > 10


def _rot(ax: float, ay: float) -> np.ndarray:
    """Small rotation about x then y."""
    cx, sx, cy, sy = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay)
    return np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]]) @ np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])


def _set_displaced(P: np.ndarray, a: float, th2: float, s: float) -> None:
    """Poses as shafts: give them (wormsim.tooth.pose's layout): the wheel and the worm's static frame moved off the
    nominal assembly (X_g = Rz(theta2), A = Trans(0, -a, 0) R0) by translations of up to 6 um and tilts of up to
    2e-4 rad, varying with s."""
    from meshgen import assembly
    from wormsim.tooth.pose import WHEEL, WORM

    c, sn = math.cos(th2), math.sin(th2)
    Xg = np.eye(4)
    Xg[:3, :3] = _rot(2e-4 * math.sin(s), -1e-4 * math.cos(s)) @ np.array([[c, -sn, 0], [sn, c, 0], [0, 0, 1]])
    Xg[:3, 3] = 1e-6 * np.array([4 * math.sin(s), -3 * math.cos(2 * s), 2.0])
    A = np.eye(4)
    A[:3, :3] = _rot(-1e-4 * math.cos(s), 1.5e-4 * math.sin(3 * s)) @ assembly.R0
    A[:3, 3] = np.array([0.0, -a, 0.0]) + 1e-6 * np.array([-2.0, 6 * math.sin(s), 3 * math.cos(s)])
    P[WHEEL : WHEEL + 12] = Xg[:3].ravel()
    P[WORM : WORM + 12] = A[:3].ravel()


def test_memo_with_displaced_poses_gives_the_same_contacts():
    """Displaced poses (shafts: and errors: hand the kernel the bodies' poses each step): the memo's bound widened by
    the poses' drift from the nominal assembly (kernel._pose_drift) keeps the contacts bit for bit, the drift is 0
    for the nominal poses and bounds the displacement of every wheel grid point, and the memo still skips."""
    from wormsim.tooth import pose

    g, S, fg, W, tooth0, margin, cap = _setup("screw_jack")
    P = pose.displaced_params(fg.params, np.zeros(g.z2))
    memo = kernel.flank_memo(fg, g.z2)
    reach = memo[1][3]
    # nominal poses: no drift
    _set_displaced(P, g.a, 0.3, 0.0)
    P0 = P.copy()
    from meshgen import assembly

    P0[pose.WHEEL : pose.WHEEL + 12] = np.array(
        [[math.cos(0.3), -math.sin(0.3), 0, 0], [math.sin(0.3), math.cos(0.3), 0, 0], [0, 0, 1, 0]]
    ).ravel()
    A0 = np.eye(4)
    A0[:3, :3], A0[:3, 3] = assembly.R0, (0.0, -g.a, 0.0)
    P0[pose.WORM : pose.WORM + 12] = A0[:3].ravel()
    assert kernel._pose_drift(P0, 0.3, reach) < 1e-15
    # the bound against the grid's points moved by the displaced poses
    pts = np.column_stack([fg.xy.reshape(-1, 2), np.broadcast_to(fg.zeta[None, :, None], fg.xy.shape[:3]).reshape(-1)])
    pts = pts[np.isfinite(pts).all(axis=1)]

    def static(Pv: np.ndarray, th2: float) -> np.ndarray:
        Xg = Pv[pose.WHEEL : pose.WHEEL + 12].reshape(3, 4)
        A = Pv[pose.WORM : pose.WORM + 12].reshape(3, 4)
        w = pts @ Xg[:, :3].T + Xg[:, 3]
        return (w - A[:, 3]) @ A[:, :3]

    for s in (0.0, 1.0, 2.5):
        _set_displaced(P, g.a, 0.3, s)
        moved = np.linalg.norm(static(P, 0.3) - static(P0, 0.3), axis=1).max()
        drift = kernel._pose_drift(P, 0.3, reach)
        assert moved <= drift <= 4 * moved, (moved, drift)
    runs: dict = {"memo": [], "none": []}
    for use in ("memo", "none"):
        bufs = [np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros((cap, 4)), np.zeros((cap, 2))]
        for i, (th1, th2) in enumerate(_states(g, 600)):
            _set_displaced(P, g.a, th2, 0.05 * i)
            ks = window_teeth_at(th2, g.z2, W, tooth0).astype(np.int64)
            args = ((fg.xy, fg.c, fg.c_range, fg.span, fg.zeta), ks, th1, th2, margin, P, tuple(bufs), 0.0)
            n = kernel.find_contacts(*args, memo if use == "memo" else None)
            runs[use].append([b[:n].copy() for b in bufs])
    assert sum(len(a[2]) > 0 for a in runs["none"]) > 250
    for a, b in zip(runs["memo"], runs["none"]):
        assert len(a[2]) == len(b[2])
        for u, v in zip(a, b):
            assert np.array_equal(u, v)
    assert np.count_nonzero(memo[0][..., 0] > 0) > 10
    assert memo[0][..., 3].max() > 1e-6  # the slices were memorised with the poses' drift


def test_merging_kernel_leaves_slice_frames_to_the_samples():
    """find_packed merging 4 slices per contact gives the slice contacts of the unmerged call bit for bit, and leaves
    their frames out (MuJoCo gets the merged ones); contact_frames on its normals, as the samples compute them
    (FlankContacts.slice_rows, flank_samples.contact_rows), are the unmerged call's frames."""
    g, S, fg, W, tooth0, margin, cap = _setup("screw_jack")
    plain = kernel.PackedKernel(fg, fg.params, cap, W, g.z2)
    merged = kernel.PackedKernel(fg, fg.params, cap, W, g.z2, merge=4)
    frames = np.zeros((cap, 9))
    loaded = 0
    for th1, th2 in _states(g, 200):
        ks = window_teeth_at(th2, g.z2, W, tooth0).astype(np.int64)
        plain.ks[:] = merged.ks[:] = ks
        merged.frame[:] = 0.0
        n = kernel.find_packed(plain.fb, plain.ib, th1, th2, margin, 0.0)
        assert kernel.find_packed(merged.fb, merged.ib, th1, th2, margin, 0.0) == n
        for f in ("pos", "nrm", "depth", "weight", "meta"):
            assert np.array_equal(getattr(plain, f)[:n], getattr(merged, f)[:n])
        assert not merged.frame[:n].any()  # left out
        kernel.contact_frames(merged.nrm, n, frames)
        assert np.array_equal(frames[:n], plain.frame[:n])
        loaded += n > 0
    assert loaded > 50


def test_memo_by_the_rate_gives_the_same_contacts():
    """The seat motor at its step's worm angle per step (36 rpm, 6.4 us: 2.4e-5 rad) with the wheel loaded and
    vibrating: the slices whose minimum lies at the profile's end or past the worm's edge are memorised by the
    motion's rate (kernel._memo_skips) and skipped, and the contacts with the memo are those without it, bit for bit."""
    g, S, fg, W, tooth0, margin, cap = _setup("seat_motor", 32)
    memo = kernel.flank_memo(fg, g.z2)
    bl = g.backlash / (2 * g.r2)
    t = np.arange(1500)
    th1 = 0.3 + 2.4e-5 * t
    th2 = g.hand * th1 * g.z1 / g.z2 + g.hand * (1.3 + 0.05 * np.sin(2 * math.pi * t / 300)) * bl
    runs: dict = {"memo": [], "none": []}
    rate_memorised = 0
    for use in ("memo", "none"):
        bufs = [np.zeros((cap, 3)), np.zeros((cap, 3)), np.zeros(cap), np.zeros((cap, 4)), np.zeros((cap, 2))]
        for a1, a2 in zip(th1, th2):
            ks = window_teeth_at(a2, g.z2, W, tooth0).astype(np.int64)
            args = ((fg.xy, fg.c, fg.c_range, fg.span, fg.zeta), ks, a1, a2, margin, fg.params, tuple(bufs), 0.0)
            n = kernel.find_contacts(*args, memo if use == "memo" else None)
            runs[use].append([b[:n].copy() for b in bufs])
            if use == "memo":
                rate_memorised = max(
                    rate_memorised, int(np.count_nonzero((memo[0][..., 0] > 0) & (memo[0][..., 5] > 0)))
                )
    assert sum(len(a[2]) > 0 for a in runs["none"]) == len(t)  # loaded throughout
    assert rate_memorised >= 4
    for a, b in zip(runs["memo"], runs["none"]):
        assert len(a[2]) == len(b[2])
        for u, v in zip(a, b):
            assert np.array_equal(u, v)
