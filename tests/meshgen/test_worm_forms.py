"""ZN, ZK, ZC worm flanks (meshgen.worm_forms) against their definitions (DIN 3975; Litvin & Fuentes ch. 19).

- ZN: the flank's section by the normal plane of the thread (ZN1) or of the space (ZN2) is a straight line at alpha_n.
- ZK, ZC: the axial section equals an independent simulation of the disc cutting: the tool placed at a dense set of
  positions of the screw motion, each position's boundary found in the axial plane by bisection on the point-in-tool
  test, the space's edge the largest over the positions (parabola through the best three).
- ZC: the axial section is concave (the thread's flank hollow), with the curvature radius the disc cuts.
- The Chebyshev table agrees with the exact solution.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshgen import worm, worm_forms
from meshgen.geometry import GearSpec, GeometryError, derive

# the seeds' gear data (scenarios/screw_jack.yaml, seat_motor.yaml, involute_41.yaml) and a 3-start set
GEARS = {
    "screw_jack": dict(wheel_teeth=24, axial_module_mm=2.5, diameter_quotient=10, backlash_mm=0.08),
    "seat_motor": dict(
        wheel_teeth=53,
        normal_module_mm=0.7,
        normal_pressure_angle_deg=10,
        lead_angle_deg=4.79,
        face_width_mm=5.0,
        backlash_mm=0.05,
    ),
    "involute_41": dict(wheel_teeth=41, axial_module_mm=10, diameter_quotient=9, backlash_mm=0.2),
    "three_start": dict(wheel_teeth=31, worm_starts=3, axial_module_mm=4, diameter_quotient=8, backlash_mm=0.1),
}


def _g(name, **kw):
    return derive(GearSpec(**GEARS[name], **kw))


def _normal_section(g, x, space: bool):
    """sigma(x): the flank's points x e_x + sigma n2 in the normal plane of the thread (space: of the space, centred
    at u = p_x / 2), from the flank as meshgen.worm evaluates it (bisection on u(x, sigma) = H(r) there)."""
    ap = abs(g.p)
    L = math.hypot(g.r1, ap)
    s, c = ap / L, g.r1 / L

    def f(sig):
        r = np.hypot(x, sig * s)
        u = sig * c + ap * np.arctan(sig * s / x)
        H = worm.half_thickness(g, r)
        return u - (g.p_x / 2 - H if space else H)

    lo, hi = np.zeros_like(x), np.full_like(x, g.p_x)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        pos = f(mid) > 0
        hi, lo = np.where(pos, mid, hi), np.where(pos, lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("name", list(GEARS))
@pytest.mark.parametrize("section", ["thread", "space"])
def test_zn_normal_section_is_straight(name, section):
    """DIN 3975 ZN1 / ZN2: straight in the normal section of the thread / space, at alpha_n; within 0.1 um (issue)."""
    g = _g(name, profile="ZN", zn_section=section)
    x = np.linspace(g.r_f1, g.r_a1, 41)
    sig = _normal_section(g, x, section == "space")
    A = np.stack([x, np.ones_like(x)], axis=1)
    coef, *_ = np.linalg.lstsq(A, sig, rcond=None)
    resid = sig - A @ coef
    assert np.max(np.abs(resid)) < 0.1e-6
    # the line's angle is the normal pressure angle (thread narrows outwards, space widens)
    want = -math.tan(g.alpha_n) if section == "thread" else math.tan(g.alpha_n)
    assert coef[0] == pytest.approx(want, abs=1e-9)


def _cut_simulation(g, r, n_pos: int = 6001):
    """Space half-width W(r) (axial, at phi = 0) by sweeping the disc through n_pos positions of the screw motion.

    Position t: the tool turned by t about the worm axis and moved |p| t along it. The axial-plane point (r, 0, z)
    is inside the tool there iff its image X' = (r cos t, -r sin t, z - |p| t) has |w| <= W_t(rho) in the tool's
    coordinates (w along the axis A, rho from it, up to the disc's tip radius worm_forms.tool_tip_radius). The upper
    boundary z_top(r, t) by bisection; W(r) = max over t (parabolic vertex through the best three)."""
    ap = abs(g.p)
    L = math.hypot(g.r1, ap)
    s, c = ap / L, g.r1 / L
    Rt = g.tool_diameter / 2
    cx = g.r1 + Rt
    w0 = worm_forms.tool_setting(g)
    an = g.alpha_n
    rho_out = worm_forms.tool_tip_radius(g)

    def Wt(rho):
        if g.profile == "ZK":
            return w0 - (rho - Rt) * math.tan(an)
        rc = g.profile_radius
        d = rho - (Rt - rc * math.sin(an))
        return np.where(np.abs(d) < rc, w0 - rc * math.cos(an) + np.sqrt(np.maximum(rc * rc - d * d, 0)), -np.inf)

    t = np.linspace(-1.0, 1.0, n_pos)
    R, T = np.meshgrid(r, t, indexing="ij")
    xs, ys = R * np.cos(T), -R * np.sin(T)

    def inside_excess(z):
        zs = z - ap * T
        d = np.stack([xs - cx, ys, zs])
        w = -s * d[1] + c * d[2]
        perp = d - w * np.stack([np.zeros_like(w), -s * np.ones_like(w), c * np.ones_like(w)])
        rho = np.sqrt(np.sum(perp * perp, axis=0))
        return np.where(rho <= rho_out, Wt(rho) - np.abs(w), -np.inf)

    z0 = ap * T + s * ys / c  # w = 0 there: the tool's mid-plane
    ok = (inside_excess(z0) > 0) & (inside_excess(z0 + g.p_x) <= 0)  # one boundary crossing in the bracket
    lo, hi = z0.copy(), z0 + g.p_x
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        ins = inside_excess(mid) > 0
        lo, hi = np.where(ins, mid, lo), np.where(ins, hi, mid)
    ztop = np.where(ok, 0.5 * (lo + hi), -np.inf)
    k = np.argmax(ztop, axis=1)
    assert np.all((k > 0) & (k < n_pos - 1)), "the cut's edge lies at the end of the swept positions"
    i = np.arange(len(r))
    ym, y0, yp = ztop[i, k - 1], ztop[i, k], ztop[i, k + 1]
    den = ym - 2 * y0 + yp
    return y0 - (yp - ym) ** 2 / (8 * den)


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor", "three_start"])
@pytest.mark.parametrize("profile", ["ZK", "ZC"])
def test_disc_forms_match_cut_simulation(name, profile):
    """ZK / ZC axial section = the independent simulation of the disc cutting within 0.5 um (issue), over the thread's
    depth; the worm's H(r) there as meshgen.worm evaluates it (the table)."""
    g = _g(name, profile=profile)
    r = np.linspace(g.r_f1, g.r_a1, 13)
    W_sim = _cut_simulation(g, r)
    W_worm = g.p_x / 2 - worm.half_thickness(g, r)
    assert np.max(np.abs(W_sim - W_worm)) < 0.5e-6


@pytest.mark.parametrize("name", list(GEARS))
@pytest.mark.parametrize("profile", ["ZN", "ZK", "ZC"])
def test_table_matches_exact(name, profile):
    """The Chebyshev table (what meshgen.worm and the contact kernel evaluate) within 1 nm of the exact solution, and
    its thickness on d1 is p_x / 2 (meshgen.worm_forms: the tool's setting)."""
    g = _g(name, profile=profile)
    r = np.linspace(*worm_forms.table_range(g), 157)
    err = np.abs(worm.half_thickness(g, r) - worm_forms.exact_half_thickness(g, r))
    assert np.max(err) < 1e-9
    assert float(worm_forms.exact_half_thickness(g, g.r1)[0]) == pytest.approx(g.p_x / 4, abs=1e-12)
    h = 1e-3 * g.m_x
    fd = (worm_forms.exact_half_thickness(g, r + h) - worm_forms.exact_half_thickness(g, r - h)) / (2 * h)
    assert np.max(np.abs(worm.half_thickness_dr(g, r) - fd)) < 1e-5


def _radius_of_curvature(f, r0, h):
    d1 = (f(r0 + h) - f(r0 - h)) / (2 * h)
    d2 = (f(r0 + h) - 2 * f(r0) + f(r0 - h)) / (h * h)
    return (1 + d1 * d1) ** 1.5 / d2


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor", "involute_41"])
def test_zc_axial_section_concave_with_the_tool_radius(name):
    """ZC (Cavex): the thread's axial profile is hollow (H'' > 0 over the thread's depth), and its curvature radius at
    d1 is the one the disc cuts (independent cut simulation: circle through three of its points, within 1 %); it lies
    within 5 % of the rack approximation rho_c cos(gamma) (cos alpha_n / cos alpha_x)^3 (the disc's arc radius seen in
    the axial section of a straight thread; measured 1.6-2.6 % above it: the helix's own curvature)."""
    g = _g(name, profile="ZC")
    r = np.linspace(g.r_f1, g.r_a1, 41)
    h = 0.05 * g.m_x
    d2 = (worm.half_thickness(g, r + h) - 2 * worm.half_thickness(g, r) + worm.half_thickness(g, r - h)) / h**2
    assert np.all(d2 > 0)
    hh = 0.1 * g.m_x
    R_table = _radius_of_curvature(lambda x: float(worm.half_thickness(g, x)), g.r1, hh)
    sim = _cut_simulation(g, np.array([g.r1 - hh, g.r1, g.r1 + hh]))
    R_sim = _radius_of_curvature(lambda x: -float(sim[int(round((x - g.r1) / hh)) + 1]), g.r1, hh)
    assert R_table == pytest.approx(R_sim, rel=0.01)
    rack = g.profile_radius * math.cos(g.gamma) * (math.cos(g.alpha_n) / math.cos(g.alpha_x)) ** 3
    assert R_table == pytest.approx(rack, rel=0.05)


def test_forms_differ_and_za_zi_unchanged():
    """ZA and ZI keep their closed forms (meshgen.worm (1), (2)); the other forms are different surfaces with the
    same thickness on d1."""
    base = GEARS["screw_jack"]
    r = np.linspace(0, 1, 9)
    H = {}
    for prof in worm_forms.FORMS:
        g = derive(GearSpec(**base, profile=prof))
        rr = g.r_f1 + r * (g.r_a1 - g.r_f1)
        H[prof] = worm.half_thickness(g, rr)
    g = derive(GearSpec(**base, profile="ZA"))
    rr = g.r_f1 + r * (g.r_a1 - g.r_f1)
    np.testing.assert_allclose(H["ZA"], g.p_x / 4 - (rr - g.r1) * math.tan(g.alpha_x), rtol=0, atol=1e-15)
    for a in worm_forms.FORMS:
        for b in worm_forms.FORMS:
            if a < b:
                assert np.max(np.abs(H[a] - H[b])) > 1e-7, (a, b)


def test_bad_tool_refused():
    """A disc too small for the thread's depth, or a ZC arc too short for it: GeometryError naming the field."""
    with pytest.raises(GeometryError, match="gear.tool_diameter_mm"):
        worm.half_thickness(_g("screw_jack", profile="ZK", tool_diameter_mm=5.0), 0.0125)
    with pytest.raises(GeometryError, match="gear.profile_radius_mm"):
        worm.half_thickness(_g("screw_jack", profile="ZC", profile_radius_mm=3.0), 0.0125)


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor", "involute_41"])
def test_zk_tends_to_zi_as_the_disc_grows(name):
    """A straight-sided disc of infinite radius is a plane at alpha_n through the normal section, and a plane in that
    setting grinds the involute helicoid (Litvin & Fuentes 19.5: ZI ground by the plane face of a disc). ZK's distance
    from ZI's closed form falls as 1 / tool diameter: below 0.1 um at 100 m (measured 0.003-0.065 um), and 10x
    smaller per decade (measured 9.9-10.1x)."""
    gi = _g(name, profile="ZI")
    r = np.linspace(gi.r_f1, gi.r_a1, 50)
    Hi = worm.half_thickness(gi, r)
    d = [np.max(np.abs(worm.half_thickness(_g(name, profile="ZK", tool_diameter_mm=D), r) - Hi)) for D in (1e4, 1e5)]
    # ~1 / tool diameter: 10x per decade of D (Litvin & Fuentes 19.5 limit); 0.1 um: bound above the measured 0.065 um
    assert d[1] < 0.1e-6
    assert 8 < d[0] / d[1] < 12


from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from meshgen import wheel  # noqa: E402


@settings(max_examples=10, deadline=None, derandomize=True, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    gear=st.fixed_dictionaries(
        {
            "worm_starts": st.integers(1, 4),
            "wheel_teeth": st.integers(20, 80),
            "axial_module_mm": st.floats(0.5, 12),
            "diameter_quotient": st.floats(6, 16),
            "normal_pressure_angle_deg": st.floats(10, 25),
            "hand": st.sampled_from(["right", "left"]),
            "profile": st.sampled_from(["ZN", "ZK", "ZC"]),
            "zn_section": st.sampled_from(["thread", "space"]),
            "tool_diameter_mm": st.one_of(st.none(), st.floats(20, 400)),
            "profile_radius_mm": st.one_of(st.none(), st.floats(1, 200)),
        }
    )
)
def test_random_gear_of_every_form_is_made_or_refused(gear):
    """Valid gear data of any form: the flank is made (H finite, the thread thinner outwards over its depth, the table
    within 1 nm of the exact solution at d1's neighbours) and the wheel checked, or GeometryError names a gear field."""
    try:
        g = derive(GearSpec(backlash_mm=0.05 * gear["axial_module_mm"], **gear))
        worm.check_worm(g, wheel.hob_radius(g))
        wheel.check_wheel(g)
    except GeometryError as exc:
        assert "gear" in str(exc)
        return
    r = np.linspace(g.r_f1, g.r_a1, 33)
    H = worm.half_thickness(g, r)
    assert np.all(np.isfinite(H)) and np.all(np.diff(H) < 0)
    rr = g.r1 + np.array([-0.5, 0.5]) * g.m_x
    assert np.max(np.abs(worm.half_thickness(g, rr) - worm_forms.exact_half_thickness(g, rr))) < 1e-9
