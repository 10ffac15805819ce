"""Contact pattern and contact stress from the exact-flank contacts (wormsim.tooth.hertz; issue 13):
the relative radius of curvature rho' of (1) against an independent fit of the two surfaces, the Hertz formula, and
the run outputs (keys, symmetry of the screw jack's pattern, report and recording) on the cached CI runs of
tests/contact3d/test_seeds.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshgen import worm
from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from wormsim.scenario import load_scenario
from wormsim.tooth import hertz as FO
from wormsim.tooth.grid import flank_grid


def averaged_pressure_reference(log, T: np.ndarray) -> np.ndarray:
    """(4) of wormsim.tooth.hertz per row of table() rows T, in numpy (the definition PatternLog.window_rows' compiled
    pass is checked against, bit for bit): the line load and curvature averaged over the window of slices centred on
    the row, within its contact line (a new line where the sample, the flank or the slice run changes); nan for a row
    without a p_H of its own."""
    n_rows = len(T)
    if not n_rows:
        return np.zeros(0)
    cv, g = log.cv, log.geo
    sg, j = T[:, 1].astype(np.int64), T[:, 2].astype(np.int64)
    k = FO._lerp_rows(cv.inv_rho, sg, j, T[:, 3])
    ok = np.isfinite(k) & (k > 0) & np.isfinite(T[:, 5]) & (T[:, 5] > 0) & (T[:, 4] > 0)
    F = np.where(ok, T[:, 4], 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):  # the contact's own line length s L, from its (3)
        L = np.where(ok, F * log.e_star * k / (math.pi * T[:, 5] ** 2), 0.0)
    length = FO.PRESSURE_LENGTH_MX * g.m_x
    n = max(1, math.ceil(length / cv.slice_width - 1e-9))
    new = np.ones(n_rows, dtype=bool)
    new[1:] = (T[1:, 0] != T[:-1, 0]) | (sg[1:] != sg[:-1]) | (j[1:] != j[:-1] + 1)
    start = np.flatnonzero(new)
    gid = np.cumsum(new) - 1
    end = np.append(start[1:], n_rows)  # one past each line's last row
    r = np.arange(n_rows)
    lo = np.maximum(start[gid], r - (n - 1) // 2)
    hi = np.minimum(end[gid], r + n // 2 + 1)
    cF, cL, cK = (np.concatenate([[0.0], np.cumsum(x)]) for x in (F, L, np.where(ok, F * k, 0.0)))
    sF, sL, sK = cF[hi] - cF[lo], cL[hi] - cL[lo], cK[hi] - cK[lo]
    with np.errstate(divide="ignore", invalid="ignore"):
        p = FO.hertz_line_pressure_pa(sF / np.maximum(sL, length), log.e_star, sK / sF)
    return np.where(ok & (sF > 0), p, np.nan)


def _quad_hessian(uv: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Hessian of the least-squares quadratic h = c0 + c1 u + c2 v + c3 u^2 / 2 + c4 u v + c5 v^2 / 2."""
    u, v = uv[:, 0], uv[:, 1]
    A = np.column_stack([np.ones_like(u), u, v, u * u / 2, u * v, v * v / 2])
    c = np.linalg.lstsq(A, h, rcond=None)[0]
    return np.array([[c[3], c[4]], [c[4], c[5]]])


def rho_rel_by_surface_fit(g, zeta, rho, c, side):
    """rho' without the gap function: the wheel flank (meshgen.wheel.space_flank) and the worm thread
    (meshgen.worm.flank_points, the thread surface itself) sampled around the contact point, each fitted as a
    quadratic height over the common tangent plane; 1/rho' = the largest eigenvalue of the difference."""
    th1 = c / (g.hand * g.z1 / g.z2)
    X0 = FO.wheel_point(g, np.array(zeta), np.array(rho), side)
    P0 = FO._static(g, X0, np.array(c))
    # worm body frame (the thread turned back by theta1); the point's thread side and start
    cb, sb = math.cos(-th1), math.sin(-th1)
    q = np.array([cb * P0[0] - sb * P0[1], sb * P0[0] + cb * P0[1], P0[2]])
    r0, phi0 = math.hypot(q[0], q[1]), math.atan2(q[1], q[0])
    u = q[2] - g.p * phi0
    s = 1 if worm.wrap(u, g.p_x) > 0 else -1
    start = int(round((u - s * float(worm.half_thickness(g, r0))) / g.p_x))
    # the normal: the gradient of the thread's implicit form, numerically (static frame)
    e = 1e-8
    grad = np.array(
        [(worm.thread_gap(g, P0 + e * d, th1) - worm.thread_gap(g, P0 - e * d, th1)) / (2 * e) for d in np.eye(3)]
    )
    n = grad / np.linalg.norm(grad)
    e1 = np.cross(n, [1.0, 0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    hh = 0.05 * g.m_x
    a, b = np.meshgrid(np.linspace(-hh, hh, 7), np.linspace(-hh, hh, 7))
    Xw = FO.wheel_point(g, zeta + a.ravel(), rho + b.ravel(), side)
    Pw = FO._static(g, Xw, np.full(a.size, c)) - P0
    Hw = _quad_hessian(np.column_stack([Pw @ e1, Pw @ e2]), Pw @ n)
    qs = worm.flank_points(g, r0 + b.ravel(), phi0 + a.ravel() / r0, s, start)
    c1, s1 = math.cos(th1), math.sin(th1)
    Pq = np.column_stack([c1 * qs[:, 0] - s1 * qs[:, 1], s1 * qs[:, 0] + c1 * qs[:, 1], qs[:, 2]]) - P0
    assert np.max(np.abs(Pq @ n)) < 0.2 * hh  # the thread patch lies on the tangent plane (same point)
    Hq = _quad_hessian(np.column_stack([Pq @ e1, Pq @ e2]), Pq @ n)
    lam, V = np.linalg.eigh(Hw - Hq)
    t = V[0, 0] * e1 + V[1, 0] * e2  # the contact line (static worm frame; wheel axis z = -y_s)
    return 1.0 / lam[1], lam, abs(t[1])


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack", "involute_41"])
def test_relative_curvature_matches_a_fit_of_the_two_surfaces(name):
    g = derive(load_scenario(SCENARIOS / f"{name}.yaml").gear)
    fg = flank_grid(g, 16)
    cv = FO.flank_curvature(g, 16)
    for j in (3, 8, 12):
        act = np.where(np.isfinite(fg.c[0, j]))[0]
        for i in (act[len(act) // 4], act[len(act) // 2], act[3 * len(act) // 4]):
            ref, lam, tz = rho_rel_by_surface_fit(g, fg.zeta[j], fg.rho[j, i], fg.c[0, j, i], +1)
            got = 1.0 / cv.inv_rho[0, j, i]
            assert abs(lam[0]) < 0.02 * lam[1], lam  # a line contact: one ~zero eigenvalue
            assert abs(got / ref - 1) < 2e-3, (j, i, got, ref)  # measured: within 3e-4
            assert abs(cv.line_tz[0, j, i] - tz) < 0.01, (j, i, cv.line_tz[0, j, i], tz)


@pytest.mark.parametrize("name,profile", [("seat_motor", "ZI"), ("screw_jack", "ZA"), ("involute_41", "ZI")])
def test_relative_curvature_at_the_pitch_point_is_the_mid_plane_rack_and_gear(name, profile):
    """In the wheel's mid-plane a worm pair is a rack (the worm's axial section, straight for ZA, nearly so for ZI)
    meshing with an involute-like wheel profile whose radius of curvature at the pitch point is r2 sin(alpha_x)
    (DIN 3975; Niemann-Winter, Maschinenelemente III). The contact line there runs nearly along the face, so rho'
    across it is about that radius. Measured: +0.3 % (seat motor), +0.4 % (screw jack), +0.5 % (involute_41)."""
    from meshgen import wheel

    g = derive(load_scenario(SCENARIOS / f"{name}.yaml", [f"gear.profile={profile}"]).gear)
    sol = wheel.space_flank(g, np.array([g.r2]), np.array([0.0]), +1)
    k, tz, _ = FO.curvature_at(g, np.array([0.0]), np.array([g.r2]), sol.beta - sol.psi, +1)
    assert abs(1 / k[0] / (g.r2 * math.sin(g.alpha_x)) - 1) < 0.01, (1 / k[0], g.r2 * math.sin(g.alpha_x))
    # 1: the contact line runs along the face (unit tangent's z component; docstring, DIN 3975 geometry)
    assert tz[0] > 0.99


def test_hertz_line_pressure_is_johnsons_p0():
    """(3) against Johnson's line contact written through the half-width: a = sqrt(4 w R / (pi E*)),
    p0 = 2 w / (pi a) (Contact Mechanics, eqs. 4.43, 4.45); steel cylinders R1 = R2 = 20 mm, w = 100 N/mm."""
    E = 1.0 / (2 * (1 - 0.3**2) / 210e9)
    R, w = 0.01, 1e5
    a = math.sqrt(4 * w * R / (math.pi * E))
    assert FO.hertz_line_pressure_pa(w, E, 1 / R) == pytest.approx(2 * w / (math.pi * a), rel=1e-12)
    assert FO.hertz_line_pressure_pa(w, E, 1 / R) == pytest.approx(606.2e6, rel=1e-3)  # by hand


KEYS = (
    "contact_pattern_centroid_face_mm",
    "contact_pattern_centroid_radius_mm",
    "contact_pattern_extent_face_mm",
    "contact_pressure_max_mpa",
    "contact_pressure_mean_mpa",
    "contact_pressure_max_face_mm",
    "contact_pressure_max_radius_mm",
)


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack", "involute_41"])
def test_flank_runs_report_pattern_and_pressure(name):
    """The CI runs of tests/contact3d/test_seeds.py (cached there): every key finite; the pattern lies on the
    face and between the wheel's root and tip; the mean pressure below the max; the extent within the face."""
    from tests.contact3d.test_seeds import run

    r = run(name)
    s, g = r["summary"], derive(r["scenario"].gear)
    for k in KEYS:
        assert np.isfinite(s[k]), (k, s[k])
    b = g.face_width * 1e3
    assert abs(s["contact_pattern_centroid_face_mm"]) < b / 2
    assert 0 < s["contact_pattern_extent_face_mm"] <= b * (1 + 1e-9)
    assert g.r_f2 * 1e3 < s["contact_pattern_centroid_radius_mm"] < g.r_a2 * 1e3 + 1e-6
    assert 0 < s["contact_pressure_mean_mpa"] < s["contact_pressure_max_mpa"]
    assert s["contact_pattern_source"].startswith("loaded")


def test_screw_jack_pattern_is_centred_on_the_mid_plane():
    """The perfect screw jack pair, worm driving: the load centroid within 2 % of the face width of the mid-plane
    (measured: -0.17 mm on a 20 mm face, CI run)."""
    from tests.contact3d.test_seeds import run

    r = run("screw_jack")
    b = derive(r["scenario"].gear).face_width * 1e3
    assert abs(r["summary"]["contact_pattern_centroid_face_mm"]) < 0.02 * b


def test_report_and_recording_show_the_pattern(tmp_path):
    """A short screw jack run with flanks: report.png's pattern panel holds the loaded cells coloured by pressure
    (the largest cell equals contact_pressure_max_mpa), and the recording holds the pattern on the wheel."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    from wormsim.contact3d.report import write_recording, write_report
    from wormsim.contact3d.runner import simulate
    from wormsim.results.recording import recorded_data, recorded_entities

    sc = load_scenario(
        SCENARIOS / "screw_jack.yaml",
        [
            "contact.geometry=flanks",
            "drive.ramp_s=0.01",
            "load.ramp_s=0.01",
            "simulation.duration_s=0.03",
            "simulation.resolution=medium",
        ],
    )
    res = simulate(sc)
    s, grid = res.summary, res.extra["flank_pattern"]
    fig, ax = plt.subplots()
    FO.draw_pattern(ax, fig, grid, res.extra["built"].geometry, s)
    pcs = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(pcs) == 1 and len(pcs[0].get_array()) > 10
    assert float(pcs[0].get_array().max()) == pytest.approx(s["contact_pressure_max_mpa"], rel=1e-9)
    assert "pressure" in fig.axes[-1].get_ylabel()  # the colour bar
    plt.close(fig)
    write_report(res, tmp_path / "report.png")
    assert (tmp_path / "report.png").stat().st_size > 10_000
    write_recording(res, tmp_path / "recording.rrd")
    assert "/assembly/wheel/contact_pattern" in recorded_entities(tmp_path / "recording.rrd")
    chunks = recorded_data(tmp_path / "recording.rrd")["/assembly/wheel/contact_pattern"]
    n_pts = sum(len(v[0]) for c in chunks for k, v in c.items() if k.endswith("positions") and v and v[0])
    assert n_pts == int((grid["load"] > 1e-3 * grid["load"].max()).sum()) * derive(sc.gear).z2


def test_extent_is_the_face_span_holding_95_percent_of_the_load():
    """contact_pattern_extent_face_mm's quantile rule on synthetic loads: an even load over the whole face gives
    0.95 b2; a load in one slice 0.95 of that slice's width; two equal end slices the span between their inner
    quantile points."""
    g = derive(load_scenario(SCENARIOS / "screw_jack.yaml").gear)
    log = FO.PatternLog.__new__(FO.PatternLog)
    log.cv = FO.flank_curvature(g, 16)
    w = log.cv.slice_width

    def rows(slices, loads):
        T = np.zeros((len(slices), 8))
        T[:, 2], T[:, 4] = slices, loads
        return T

    # 0.95 quantile rule of contact_pattern_extent_face_mm on an even load: 0.95 b2 (by hand)
    assert log.extent_face_m(rows(np.arange(16), np.ones(16))) == pytest.approx(0.95 * g.face_width, rel=1e-12)
    assert log.extent_face_m(rows([5], [3.0])) == pytest.approx(0.95 * w, rel=1e-12)
    # half the load in slice 0, half in slice 15: 2.5 % lies 0.05 w into slice 0, 97.5 % 0.95 w into slice 15
    assert log.extent_face_m(rows([0, 15], [1.0, 1.0])) == pytest.approx(g.face_width - 0.1 * w, rel=1e-12)


def test_pressure_maximum_is_the_line_load_averaged_over_one_module_of_line():
    """hertz (4): the peak p_H of the line load averaged over l_H = m_x of contact line centred on each contact (its
    contacts' own line lengths s L, at least l_H per window), not one contact's (3). A contact entering the line with
    a vanishing share s of its slice divides a vanishing force by a vanishing length in (3) (here 1e-4 N on
    s = 1e-7: p_H 1.7 GPa; the screw jack CI run had 2069 MPa from < 0.005 N); in (4) its window counts over l_H.
    Screw jack, 16 slices: m_x 2.5 mm over 1.41 mm slices, windows of 2 slices (the contact's and the next)."""
    g = derive(load_scenario(SCENARIOS / "screw_jack.yaml").gear)
    log = FO.PatternLog.__new__(FO.PatternLog)
    log.geo, log.e_star, log.cv = g, 1.3e11, FO.flank_curvature(g, 16)
    cv = log.cv
    n = math.ceil(FO.PRESSURE_LENGTH_MX * g.m_x / cv.slice_width - 1e-9)
    assert n == 2
    f = {j: int(np.flatnonzero(np.isfinite(cv.inv_rho[0, j]) & np.isfinite(cv.line_len[0, j]))[20]) for j in range(16)}
    k = {j: cv.inv_rho[0, j, f[j]] for j in range(16)}
    # sample 0: a line over slices 4..9, slice 4 entering (1e-4 N on s = 1e-7), slice 9 half covered; sample 1: one
    # contact covering a fifth of slice 12 (line shorter than l_H)
    line = {(0, 4): (1e-4, 1e-7), (0, 5): (10.0, 1.0), (0, 6): (12.0, 1.0), (0, 7): (14.0, 1.0), (0, 8): (12.0, 1.0)}
    line |= {(0, 9): (8.0, 0.5), (1, 12): (6.0, 0.2)}
    sL = {key: s_ * cv.line_len[0, key[1], f[key[1]]] for key, (F, s_) in line.items()}
    rows = []
    for (i, j), (F, _) in line.items():
        p3 = FO.hertz_line_pressure_pa(F / sL[i, j], log.e_star, k[j])  # the contact's own (3), as _rows makes it
        rows.append([i, 0, j, f[j], F, p3, cv.zeta[j], 28e-3])
    T = np.array(rows).astype(np.float32).astype(float)  # the log's rows as its float32 buffer holds them
    log.buf, log.m, log._rows = T[:, :6].astype(np.float32), len(T), None
    log.rho3 = np.ascontiguousarray(np.broadcast_to(cv.rho, cv.inv_rho.shape))
    assert T[0, 5] > 1.5e9  # the entering contact's (3)

    def by_hand(keys):
        F = np.array([line[key][0] for key in keys])
        K = np.array([k[key[1]] for key in keys])
        w = F.sum() / max(sum(sL[key] for key in keys), g.m_x)
        return math.sqrt(w * log.e_star * (F * K).sum() / F.sum() / math.pi)

    # each contact's window within its line: slices j and j + 1, clipped to the line
    expect = {key: by_hand([x for x in ((key[0], key[1]), (key[0], key[1] + 1)) if x in line]) for key in line}
    p = log.window_rows(np.array([0.0, 1.0]), (0.0, 1.0))[1]  # every row: samples 0 and 1, F_n > 0
    assert p == pytest.approx(list(expect.values()), rel=1e-6)
    assert np.array_equal(p, averaged_pressure_reference(log, T))
    s = log.summary(np.array([0.0, 1.0]), (0.0, 1.0))
    kmax = max(expect, key=expect.get)
    assert s["contact_pressure_max_mpa"] == pytest.approx(expect[kmax] * 1e-6, rel=1e-6)
    assert s["contact_pressure_max_mpa"] < 1000.0  # not the entering contact's 1.7 GPa
    assert s["contact_pressure_max_face_mm"] == pytest.approx(cv.zeta[kmax[1]] * 1e3)
    fn, p3 = T[:, 4], T[:, 5]
    assert s["contact_pressure_mean_mpa"] == pytest.approx((fn * p3).sum() / fn.sum() * 1e-6, rel=1e-12)


def test_window_rows_are_the_tables_rows_in_the_window_bit_for_bit():
    """PatternLog.window_rows (compiled, one pass over the log) against its definition: table()'s rows with F_n > 0 in
    the window's samples and (4) of the whole table (averaged_pressure_reference) at those rows, bit for bit (nan where (4) has no
    value); the grid's cells against numpy's add.at and maximum.at. A random log of the screw jack's 16 slices: 40 samples, contact lines on both flanks over runs of
    consecutive slices with gaps, zero and negative forces, contacts without a p_H (3)."""
    g = derive(load_scenario(SCENARIOS / "screw_jack.yaml").gear)
    log = FO.PatternLog.__new__(FO.PatternLog)
    log.geo, log.e_star, log.cv = g, 1.3e11, FO.flank_curvature(g, 16)
    cv = log.cv
    log.rho3 = np.ascontiguousarray(np.broadcast_to(cv.rho, cv.inv_rho.shape))
    rng = np.random.default_rng(7)
    rows = []
    for i in range(40):
        for sg in (0, 1):
            j0 = int(rng.integers(0, 12))
            for j in range(j0, min(16, j0 + int(rng.integers(1, 8)))):
                if rng.random() < 0.1:
                    continue  # a gap: a new line after it
                f = float(rng.uniform(0.0, cv.inv_rho.shape[2] - 1))
                fn = float(rng.choice([0.0, -1.0, *rng.uniform(0.1, 50.0, 6)]))
                ph = float(rng.choice([np.nan, *rng.uniform(1e8, 1e9, 6)]))
                rows.append([i, sg, j, f, fn, ph])
    log.buf = np.array(rows, dtype=np.float32)
    log.m, log._rows = len(rows), None
    t_s = np.arange(40) * 1e-3
    window = (8e-3, 31e-3)
    T = log.table()
    keep = ((t_s >= window[0]) & (t_s <= window[1]))[T[:, 0].astype(int)] & (T[:, 4] > 0)
    sel, pavg = log.window_rows(t_s, window)
    assert 0 < len(sel) < len(T)
    assert np.array_equal(sel, T[keep], equal_nan=True)
    assert np.array_equal(pavg, averaged_pressure_reference(log, T)[keep], equal_nan=True)
    assert 50 < np.isfinite(pavg).sum() < len(pavg)  # both kinds of row
    # the grid's cells (compiled) against numpy's add.at / maximum.at over the same rows
    log.fc = type("FC", (), {"grid": flank_grid(g, 16)})()
    grid = log.grid(t_s, window)
    load, pmax = np.zeros(cv.inv_rho.shape), np.zeros(cv.inv_rho.shape)
    sg, j = sel[:, 1].astype(int), sel[:, 2].astype(int)
    i = np.clip(np.rint(sel[:, 3]).astype(int), 0, cv.inv_rho.shape[2] - 1)
    np.add.at(load, (sg, j, i), sel[:, 4])
    k = np.isfinite(pavg)
    np.maximum.at(pmax, (sg[k], j[k], i[k]), pavg[k])
    assert np.array_equal(grid["load"], load) and np.array_equal(grid["pressure_max_pa"], pmax)
    assert (load > 0).sum() > 50


def test_flank_curvature_is_cached_on_disk_per_gear_grid_and_profile_count(tmp_path, monkeypatch):
    """flank_curvature's disk cache (meshgen.cache): a second process's call loads what the first computed, equal
    bit for bit; another profile count or gear is its own entry; None takes the grid's N_PROFILE when called."""
    from wormsim.tooth import grid

    monkeypatch.setenv("WORMSIM_CACHE", str(tmp_path))
    g = derive(load_scenario(SCENARIOS / "screw_jack.yaml").gear)
    FO._flank_curvature_cached.cache_clear()
    a = FO.flank_curvature(g, 8, 16)
    files = sorted(p.name for p in tmp_path.glob("flankcurv-*.pkl"))
    assert len(files) == 1
    FO._flank_curvature_cached.cache_clear()  # as a new process: from disk
    b = FO.flank_curvature(g, 8, 16)
    assert b is not a
    for k in ("inv_rho", "line_tz", "line_len", "rho", "zeta"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    FO.flank_curvature(g, 8, 24)
    FO.flank_curvature(derive(load_scenario(SCENARIOS / "seat_motor.yaml").gear), 8, 16)
    assert len(list(tmp_path.glob("flankcurv-*.pkl"))) == 3
    monkeypatch.setattr(grid, "N_PROFILE", 16)
    assert FO.flank_curvature(g, 8) is FO.flank_curvature(g, 8, 16)
    FO._flank_curvature_cached.cache_clear()
