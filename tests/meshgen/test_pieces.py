"""Convex collision pieces, visual meshes, mass properties, cache, and property tests over gear data."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from meshgen import pieces, wheel, worm
from meshgen.cache import cache_key
from meshgen.geometry import GeometryError, derive
from tests._meshgen_common import clearance_to_worm, face_samples, gear_with, seed_geometry
from wormsim.scenario import Gear


@pytest.fixture(scope="module", autouse=True)
def _cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("WORMSIM_CACHE", str(tmp_path_factory.mktemp("wormsim-cache")))
    yield
    mp.undo()


@pytest.fixture(scope="module")
def seat_medium():
    return pieces.build_gear_set(seed_geometry("seat_motor"), "medium")


def _is_own_hull(m) -> bool:
    return (
        m.is_watertight
        and m.volume > 0
        and m.is_convex
        and abs(m.convex_hull.volume - m.volume) <= 1e-9 * m.convex_hull.volume
    )


def test_pieces_are_convex_watertight(seat_medium):
    gs = seat_medium
    assert len(gs.worm_pieces) > 100 and len(gs.wheel_tooth_pieces) >= gs.resolution.wheel_slabs
    assert all(_is_own_hull(p) for p in gs.worm_pieces + gs.wheel_tooth_pieces)
    g = gs.geometry
    # worm pieces stay in the threaded length, wheel pieces within the face width
    assert max(np.abs(p.bounds[:, 2]).max() for p in gs.worm_pieces) <= g.worm_length / 2 + 1e-12
    assert max(np.abs(p.bounds[:, 2]).max() for p in gs.wheel_tooth_pieces) <= g.face_width / 2 + 1e-12
    assert gs.worm_core_radius_m == g.r_f1
    # tooth 0's pieces are centred on tooth_angle_rad(0)
    c = np.mean([p.centroid for p in gs.wheel_tooth_pieces], axis=0)
    assert math.atan2(c[1], c[0]) == pytest.approx(gs.tooth_angle_rad(0), abs=0.02 * 2 * math.pi / g.z2)
    assert gs.tooth_angle_rad(1) - gs.tooth_angle_rad(0) == pytest.approx(2 * math.pi / g.z2)


def _assert_pieces_cover_flanks(gs, seed: int = 1, n: int = 3000):
    """Independent random sample of the exact active flanks: signed distance to the union of pieces within the
    reported [min_signed, max_signed] band, widened by 10 % of max + 0.1 um (the report is itself sampled)."""
    g = gs.geometry
    rng = np.random.default_rng(seed)
    # worm: random (r, phi) in one turn around the middle
    r = rng.uniform(g.throat_radius, g.r_a1, n)
    phi = rng.uniform(-math.pi, math.pi, n)
    side = rng.choice([-1, 1], n)
    P = np.concatenate([worm.flank_points(g, r[side == s], phi[side == s], s) for s in (-1, 1)])
    d = pieces.union_signed_distance(gs.worm_pieces, P) * 1e6
    e = gs.piece_error_um["worm"]
    assert d.min() >= e["min_signed"] - 0.1 * e["max"] - 0.1
    assert d.max() <= e["max_signed"] + 0.1 * e["max"] + 0.1
    # wheel: random (rho, zeta) on the conjugate active flank
    zeta = rng.uniform(-g.face_width / 2, g.face_width / 2, n)
    lo = g.a - np.sqrt(g.r_a1**2 - zeta**2)
    rho = lo + rng.uniform(0, 1, n) * (wheel.tip_rho(g, zeta) - lo)
    a, b = wheel.tooth_flanks(g, rho, zeta)
    conj = wheel.space_flank(g, rho, zeta, +1).interior, wheel.space_flank(g, rho, zeta, -1).interior
    P = np.concatenate([np.stack([rho * np.cos(p), rho * np.sin(p), zeta], -1)[c] for p, c in zip((a, b), conj)])
    d = pieces.union_signed_distance(gs.wheel_tooth_pieces, P) * 1e6
    e = gs.piece_error_um["wheel"]
    assert d.min() >= e["min_signed"] - 0.1 * e["max"] - 0.1
    assert d.max() <= e["max_signed"] + 0.1 * e["max"] + 0.1


def test_pieces_cover_exact_flank_within_reported_error(seat_medium):
    _assert_pieces_cover_flanks(seat_medium)


def test_piece_error_shrinks_with_resolution():
    g = seed_geometry("seat_motor")
    errs = {r: pieces.build_gear_set(g, r).piece_error_um for r in ("coarse", "medium", "fine")}
    assert errs["coarse"]["worm"]["max"] > errs["medium"]["worm"]["max"] > errs["fine"]["worm"]["max"]
    assert errs["coarse"]["wheel"]["rms"] > errs["medium"]["wheel"]["rms"] > errs["fine"]["wheel"]["rms"]
    assert errs["medium"]["worm"]["max"] < 15 and errs["medium"]["wheel"]["max"] < 15  # um, seat motor
    assert errs["medium"]["worm"]["min_signed"] >= -1e-6  # um; helical chords lie inside the thread: no bulge


def test_wheel_pieces_never_interfere_with_exact_worm(seat_medium):
    """Points on every face of the wheel-tooth pieces, 7 teeth, over one mesh cycle: clearance to the exact worm
    >= 0 and >= (j/2) cos(alpha_n) cos(gamma) minus the reported bulge of the pieces (0.5 um sampling margin)."""
    gs = seat_medium
    g = gs.geometry
    pts = np.concatenate([face_samples(p) for p in gs.wheel_tooth_pieces])
    mins = np.array([clearance_to_worm(g, pts, th)[1].min() for th in np.linspace(0, 2 * math.pi / g.z1, 25)])
    bulge = -gs.piece_error_um["wheel"]["min_signed"] * 1e-6
    assert mins.min() > 0
    assert mins.min() >= g.backlash / 2 * math.cos(g.alpha_n) * math.cos(g.gamma) - bulge - 0.5e-6


def test_worm_pieces_never_interfere_with_exact_wheel(seat_medium):
    """Points on the worm pieces (middle turn) in the wheel frame, against the exact tooth: the circumferential
    gap rho (psi - psi_a) / rho (psi_b - psi) to the nearest tooth's flanks is never negative."""
    from meshgen import assembly

    gs = seat_medium
    g = gs.geometry
    mid = [p for p in gs.worm_pieces if abs(p.centroid[2]) < g.p_x * 1.5]
    pts = np.concatenate([face_samples(p, 3) for p in mid])
    worst = np.inf
    for th1 in np.linspace(0, 2 * math.pi / g.z1, 13):
        m = np.linalg.inv(assembly.wheel_to_assembly(assembly.wheel_angle(g, th1))) @ assembly.worm_to_assembly(th1, g)
        P = assembly.transform_points(m, pts)
        rho, zeta = np.hypot(P[:, 0], P[:, 1]), P[:, 2]
        inside = (np.abs(zeta) <= g.face_width / 2) & (rho >= wheel.root_rho(g, zeta)) & (rho <= wheel.tip_rho(g, zeta))
        P, rho, zeta = P[inside], rho[inside], zeta[inside]
        pitch = 2 * math.pi / g.z2
        t0 = wheel.tooth_angle(g, 0)
        psi = (np.arctan2(P[:, 1], P[:, 0]) - t0 + pitch / 2) % pitch - pitch / 2 + t0  # into tooth 0's sector
        a, b = wheel.tooth_flanks(g, rho, zeta)
        gap = np.maximum(a - psi, psi - b) * rho  # > 0 outside the tooth
        worst = min(worst, gap.min())
    assert worst > 0


def test_visual_meshes_watertight_volume_inertia(seat_medium):
    """Wheel: volume and axial inertia against quadrature of the exact flanks (teeth) and the revolved rim."""
    gs = seat_medium
    g = gs.geometry
    for m in (gs.worm_visual, gs.wheel_visual):
        assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, 201)
    s = np.linspace(0, 1, 201)
    lo, hi = wheel.root_rho(g, zeta), wheel.tip_rho(g, zeta)
    R = lo[None] + s[:, None] * (hi - lo)[None]
    Z = np.broadcast_to(zeta[None], R.shape)
    a, b = wheel.tooth_flanks(g, R, Z)
    w = (b - a) * (hi - lo)[None]  # d rho = (hi - lo) ds
    v_teeth = g.z2 * np.trapezoid(np.trapezoid(w * R, s, axis=0), zeta)
    i_teeth = g.z2 * np.trapezoid(np.trapezoid(w * R**3, s, axis=0), zeta)
    r_bore = 0.35 * g.r_f2
    v_rim = np.trapezoid(math.pi * (lo**2 - r_bore**2), zeta)
    i_rim = np.trapezoid(math.pi / 2 * (lo**4 - r_bore**4), zeta)
    assert gs.wheel_visual.volume == pytest.approx(v_teeth + v_rim, rel=2e-3)
    assert gs.wheel_visual.moment_inertia[2, 2] == pytest.approx(i_teeth + i_rim, rel=2e-3)


def test_cache_roundtrip_and_key(tmp_path, monkeypatch):
    monkeypatch.setenv("WORMSIM_CACHE", str(tmp_path))
    g = seed_geometry("screw_jack")
    a = pieces.build_gear_set(g, "coarse")
    files = list(tmp_path.glob("gearset-*.pkl"))
    assert len(files) == 1
    b = pieces.build_gear_set(g, "coarse")
    assert np.array_equal(a.worm_visual.vertices, b.worm_visual.vertices)
    assert a.piece_error_um == b.piece_error_um
    coarse, medium = pieces.RESOLUTIONS["coarse"], pieces.RESOLUTIONS["medium"]
    assert cache_key(pieces.gear_set_key(g, coarse)) != cache_key(pieces.gear_set_key(g, medium))
    g2 = gear_with("screw_jack", backlash_mm=0.1)
    assert cache_key(pieces.gear_set_key(g, coarse)) != cache_key(pieces.gear_set_key(g2, coarse))


# ----------------------------------------------------------------------------- property tests

valid_gears = st.builds(
    lambda profile, hand, z1, z2, m, alpha, q, bl: Gear(
        profile=profile,
        hand=hand,
        worm_starts=z1,
        wheel_teeth=z2,
        axial_module_mm=m,
        normal_pressure_angle_deg=alpha,
        diameter_quotient=q,
        backlash_mm=bl * m,
    ),
    st.sampled_from(["ZI", "ZA"]),
    st.sampled_from(["right", "left"]),
    st.integers(1, 3),
    st.integers(28, 70),
    st.floats(0.5, 6.0),
    st.floats(18.0, 25.0),
    st.floats(8.0, 14.0),
    st.floats(0.0, 0.08),
)


@settings(
    max_examples=5,
    deadline=None,
    derandomize=True,
    phases=[Phase.explicit, Phase.generate],
    suppress_health_check=[HealthCheck.too_slow],
)
@given(valid_gears)
def test_property_valid_gears_watertight_and_never_interfering(gear):
    g = derive(gear)
    gs = pieces.build_gear_set(g, "coarse", use_cache=False)
    for m in (gs.worm_visual, gs.wheel_visual):
        assert m.is_watertight and m.is_winding_consistent and m.volume > 0
        # what an STL reader sees (it merges vertices closer than 1e-8): still the same closed solid
        buf = io.BytesIO()
        m.export(buf, file_type="stl")
        buf.seek(0)
        back = trimesh.load(buf, file_type="stl")
        assert back.is_watertight and back.volume == pytest.approx(m.volume, rel=1e-6)  # STL is float32
    assert all(p.is_convex and p.is_watertight for p in gs.wheel_tooth_pieces + gs.worm_pieces)
    # the reported piece error is honest for any gear, and the pieces are conservative: the worm pieces never
    # stand proud of the exact flank (ZA corrected by worm_shrink), the wheel pieces by under 3e-3 m_x
    _assert_pieces_cover_flanks(gs, n=1500)
    assert gs.piece_error_um["worm"]["min_signed"] >= -1e-3 * g.m_x * 1e6
    assert gs.piece_error_um["wheel"]["min_signed"] >= -3e-3 * g.m_x * 1e6
    pts, conj = pieces.wheel_active_flank_points(g, n_rho=13, n_zeta=17)
    mins = np.array([clearance_to_worm(g, pts[conj], th)[0].min() for th in np.linspace(0, 2 * math.pi / g.z1, 9)])
    assert mins.min() >= g.backlash / 2 - 2e-8 * g.m_x / 1e-3


invalid_gears = st.one_of(
    # undercut: small pressure angle, few teeth
    st.builds(
        lambda z2, alpha, m: (
            dict(wheel_teeth=z2, normal_pressure_angle_deg=alpha, axial_module_mm=m, diameter_quotient=10),
            r"gear\.(normal_pressure_angle_deg|wheel_teeth)",
        ),
        st.integers(10, 24),
        st.floats(5.0, 9.0),
        st.floats(1.0, 10.0),
    ),
    # face width beyond what the root torus leaves
    st.builds(
        lambda f, m: (
            dict(wheel_teeth=40, axial_module_mm=m, diameter_quotient=10, face_width_mm=f * 2 * (m * 5 + m)),
            r"gear\.face_width_mm",
        ),
        st.floats(1.0, 1.2),
        st.floats(0.5, 5.0),
    ),
    # backlash leaving no tooth
    st.builds(
        lambda b, m: (
            dict(wheel_teeth=40, axial_module_mm=m, diameter_quotient=10, backlash_mm=b * math.pi * m),
            r"gear\.backlash_mm",
        ),
        st.floats(0.41, 0.6),
        st.floats(0.5, 5.0),
    ),
)


@settings(max_examples=12, deadline=None, derandomize=True, phases=[Phase.explicit, Phase.generate])
@given(invalid_gears)
def test_property_invalid_data_is_a_clear_input_error(case):
    """Undercut, a too wide face or a backlash leaving no tooth: always GeometryError naming the field."""
    fields, pattern = case
    with pytest.raises(GeometryError, match=pattern):
        pieces.build_gear_set(derive(Gear(**fields)), "coarse", use_cache=False)


def test_collision_pieces_against_each_other_over_mesh_cycle(seat_medium):
    """What MuJoCo sees: the convex worm pieces (middle turns) and the wheel-tooth pieces of 7 teeth, placed by
    meshgen.assembly over one mesh cycle: no intersection volume (manifold3d), minimum gap between
    (j/2) cos(alpha_n) cos(gamma) minus the reported wheel bulge and the exact value (measured seat motor,
    conservative pieces: coarse 24.33, medium 24.24, fine 24.48 um against 24.53 exact)."""
    import manifold3d as mf

    from meshgen import assembly

    gs = seat_medium
    g = gs.geometry
    mm = 1000.0
    worm_near = [p for p in gs.worm_pieces if abs(p.centroid[2]) < 3 * g.p_x]
    W = mf.Manifold.compose([mf.Manifold.hull_points(np.asarray(p.vertices) * mm) for p in worm_near])
    teeth = []
    for k in range(-3, 4):
        rot = assembly.wheel_to_assembly(2 * math.pi * k / g.z2)[:3, :3]
        teeth += [mf.Manifold.hull_points(np.asarray(p.vertices) @ rot.T * mm) for p in gs.wheel_tooth_pieces]
    H = mf.Manifold.compose(teeth)
    normal = g.backlash / 2 * math.cos(g.alpha_n) * math.cos(g.gamma)
    bulge = -gs.piece_error_um["wheel"]["min_signed"] * 1e-6
    gaps = []
    for th1 in np.linspace(0.0, 2 * math.pi / g.z1, 13)[:-1]:
        m = np.linalg.inv(assembly.wheel_to_assembly(assembly.wheel_angle(g, th1))) @ assembly.worm_to_assembly(th1, g)
        m[:3, 3] *= mm
        w = W.transform(m[:3, :4])
        assert (w ^ H).volume() == 0.0
        gaps.append(w.min_gap(H, 3 * normal * mm) / mm)
    assert min(gaps) >= normal - bulge - 0.5e-6
    assert min(gaps) <= normal + 0.5e-6
