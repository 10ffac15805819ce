"""Worm flanks: seed 003's involute helicoid (ZI), the straight axial profile (ZA), lead and pressure angle."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from meshgen import meshes, worm
from meshgen.geometry import GearGeometry
from tests._meshgen_common import gear_with, seed_geometry


def _flank_vertices(g: GearGeometry, mesh):
    """Vertices of the worm mesh that lie on a flank (away from root, tip and the trimmed ends), with their side."""
    V = np.asarray(mesh.vertices)
    r = np.hypot(V[:, 0], V[:, 1])
    phi = np.arctan2(V[:, 1], V[:, 0])
    sel = (r > g.r_f1 + 0.05 * g.m_x) & (r < g.r_a1 - 0.05 * g.m_x) & (np.abs(V[:, 2]) < g.worm_length / 2 - g.p_x)
    u = worm.wrap(V[:, 2] - g.p * phi, g.p_x)
    return V[sel], np.sign(u[sel])


def _seed_involute_helicoid(g: GearGeometry, t, theta, side):
    """Seed 003: x = r_b cos(theta+t) + r_b t sin(theta+t), y = r_b sin(theta+t) - r_b t cos(theta+t), z = p theta;
    the opposite flank is the same surface unwound the other way (t -> -t). Right hand (p > 0) as in the seed."""
    t = side * t
    x = g.r_b * np.cos(theta + t) + g.r_b * t * np.sin(theta + t)
    y = g.r_b * np.sin(theta + t) - g.r_b * t * np.cos(theta + t)
    return np.stack([x, y, g.p * theta], -1)


@pytest.fixture(scope="module")
def seat():
    g = seed_geometry("seat_motor")
    return g, meshes.worm_mesh(g)


@pytest.mark.parametrize("name", ["seat_motor", "involute_41"])
def test_zi_mesh_vertices_on_seed_involute_helicoid(name):
    """Every flank vertex of the worm mesh lies on seed 003's helicoid (residual < 1e-6 m_x).

    The flank of side s is the seed surface shifted along the axis by s C, C = p_x/4 + p (t1 - atan t1)
    (thread thickness p_x/2 on d1); for a vertex at radius r, t = sqrt(r^2/r_b^2 - 1), theta from z.
    """
    g = seed_geometry(name)
    mesh = meshes.worm_mesh(g, segments_per_turn=24, n_flank=6)
    V, side = _flank_vertices(g, mesh)
    assert len(V) > 100 and g.r_b < g.r_f1
    t = np.sqrt(np.hypot(V[:, 0], V[:, 1]) ** 2 / g.r_b**2 - 1)
    t1 = math.sqrt(g.r1**2 / g.r_b**2 - 1)
    C = g.p_x / 4 + g.p * (t1 - math.atan(t1))
    theta = (V[:, 2] - side * C) / g.p
    S = _seed_involute_helicoid(g, t, theta, side)
    S[:, 2] += side * C
    resid = np.linalg.norm(S - V, axis=1)
    assert resid.max() < 1e-6 * g.m_x, resid.max() / g.m_x


def test_za_mesh_vertices_on_straight_axial_profile():
    """ZA: in every axial section the flank is a straight line of slope tan(alpha_x) (residual < 1e-6 m_x)."""
    g = gear_with("involute_41", profile="ZA")
    V, side = _flank_vertices(g, meshes.worm_mesh(g, segments_per_turn=24, n_flank=6))
    r = np.hypot(V[:, 0], V[:, 1])
    phi = np.arctan2(V[:, 1], V[:, 0])
    u = worm.wrap(V[:, 2] - g.p * phi, g.p_x)
    line = side * (g.p_x / 4 - (r - g.r1) * math.tan(g.alpha_x))
    assert np.abs(u - line).max() < 1e-6 * g.m_x


def test_measured_lead_matches_input(seat):
    """Lead measured from the mesh: along one flank vertex ring (one radius), z against the unwrapped polar angle."""
    g, mesh = seat
    V, side = _flank_vertices(g, mesh)
    r = np.hypot(V[:, 0], V[:, 1])
    ring = V[(np.abs(r - np.median(r)) < 1e-9) & (side > 0)]
    if len(ring) < 50:  # median may fall between profile radii: take the most populated radius instead
        vals, counts = np.unique(np.round(r[side > 0], 12), return_counts=True)
        ring = V[side > 0][np.abs(r[side > 0] - vals[np.argmax(counts)]) < 1e-9]
    ring = ring[np.argsort(ring[:, 2])]
    phi = np.unwrap(np.arctan2(ring[:, 1], ring[:, 0]))
    slope = np.polyfit(phi, ring[:, 2], 1)[0]
    lead = abs(slope) * 2 * math.pi
    assert len(ring) > 50
    assert lead == pytest.approx(g.z1 * math.pi * g.m_x, rel=1e-9)
    # lead angle at d1 from the measured lead: tan(gamma) = lead / (pi d1), to 0.01 deg
    assert math.degrees(math.atan(lead / (math.pi * g.d1))) == pytest.approx(4.79, abs=0.01)


def _normal_pressure_angle_deg(points_fn, r, phi=0.3, h=1e-7):
    """sin(alpha_n) = |n . e_r| with n from central differences of a surface (r, phi) -> point at (r, phi)."""
    dr = (points_fn(r + h, phi) - points_fn(r - h, phi)) / (2 * h)
    dp = (points_fn(r, phi + h) - points_fn(r, phi - h)) / (2 * h)
    n = np.cross(dr, dp)
    n /= np.linalg.norm(n)
    e_r = np.array([math.cos(phi), math.sin(phi), 0.0])
    return math.degrees(math.asin(abs(float(n @ e_r))))


@pytest.mark.parametrize("name,alpha_deg", [("seat_motor", 10.0), ("involute_41", 20.0)])
def test_zi_normal_pressure_angle_at_d1(name, alpha_deg):
    """The seed-003 surface with geometry's r_b (cos gamma_b = cos gamma cos alpha_n) has alpha_n at d1 (0.01 deg)."""
    g = seed_geometry(name)

    def seed_pt(r, phi, side=1):
        t = math.sqrt(r * r / g.r_b**2 - 1)
        theta = phi - t + math.atan(t)  # polar angle of the seed point is theta + t - atan t
        return _seed_involute_helicoid(g, np.array(t), np.array(theta), 1)

    assert _normal_pressure_angle_deg(seed_pt, g.r1) == pytest.approx(alpha_deg, abs=0.01)
    # and the implemented flank (worm.flank_points) agrees, both flanks
    for side in (-1, 1):
        fn = functools.partial(worm.flank_points, g, side=side)
        assert _normal_pressure_angle_deg(fn, g.r1) == pytest.approx(alpha_deg, abs=0.01)


def test_za_normal_pressure_angle_at_d1():
    g = gear_with("involute_41", profile="ZA", normal_pressure_angle_deg=15.0)
    for side in (-1, 1):
        fn = functools.partial(worm.flank_points, g, side=side)
        # the normal_pressure_angle_deg=15.0 input, at the pitch radius (DIN 3975 ZA: tan a_x = tan a_n / cos gamma)
        assert _normal_pressure_angle_deg(fn, g.r1) == pytest.approx(15.0, abs=0.01)


def test_thread_thickness_on_d1_and_left_hand_mirror():
    g = seed_geometry("involute_41")
    assert 2 * float(worm.half_thickness(g, g.r1)) == pytest.approx(g.p_x / 2, abs=1e-12)
    gl = gear_with("involute_41", hand="left")
    assert gl.p == pytest.approx(-g.p)
    # a left-hand worm is the mirror image z -> -z of the right-hand one
    r, phi = np.linspace(g.r_f1, g.r_a1, 7), np.linspace(-1, 1, 7)
    right = worm.flank_points(g, r, phi, +1)
    left = worm.flank_points(gl, r, phi, -1)
    assert np.allclose(left, right * np.array([1, 1, -1]), atol=1e-12)


def test_worm_mesh_watertight_volume_inertia(seat):
    """Volume and axial inertia against the exact integrals: the thread fills the fraction 2 H(r) / p_x of every
    axial line at radius r (averaged over phi), so V = pi r_f1^2 b1 + int 2H/p_x 2 pi r b1 dr, I_zz likewise."""
    g, mesh = seat
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    r = np.linspace(g.r_f1, g.r_a1, 2001)
    frac = 2 * worm.half_thickness(g, r) / g.p_x * g.z1
    b = g.worm_length
    vol = math.pi * g.r_f1**2 * b + np.trapezoid(frac * 2 * math.pi * r * b, r)
    izz = math.pi * g.r_f1**4 * b / 2 + np.trapezoid(frac * 2 * math.pi * r**3 * b, r)
    assert mesh.volume == pytest.approx(vol, rel=2e-3)
    assert mesh.moment_inertia[2, 2] == pytest.approx(izz, rel=3e-3)
    assert np.allclose(mesh.bounds[:, 2], [-b / 2, b / 2], atol=1e-9)
