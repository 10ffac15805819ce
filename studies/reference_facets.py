"""Issue 13's reference figure (an exact-surface simulator fed `wormsim mesh`'s STL: screw jack F_t p2p 40-50 N at
400 N mean) against our exact flanks (1.64 N): how much of it the STL's triangle facets can give:
docs/decisions/0012-reference-simulator-facets.md.

(a) chordal deviation of the exported meshes (meshgen.meshes, what worm.stl / wheel.stl hold) from the exact flanks
    on the working flanks: wheel, exact flank points of tooth 0 (the flank grid) against the wheel mesh (a ray along
    the circle through each point -> the facet's polar angle, times the flank normal's share); worm, points sampled
    on the worm mesh's flank facets against the closed-form thread (meshgen.worm.thread_gap).
(b) the mesh stiffness k_mesh = dF_t / d(r2 lag) of the exact-flank kernel at the CI load (quasi-static, the worm set
    over a mesh cycle, the wheel at the conjugate angle minus a fixed lag, as studies/variant_harmonics.py), and
    k_mesh x deviation at 1x and 0.66x.
(c) the wheel flank replaced by its facetted version (the grid's polar angles taken from the wheel mesh's facets:
    linear between the STL's vertices): quasi-static F p2p at the fixed lag and the TE p2p at constant load, and the
    screw jack's CI run (tests/contact3d/test_seeds_pieces.py) with that grid, F_t and TE p2p; the same with the worm's
    facets (worm_facet_recess; in the kernel for the runs, worm_facet_kernel) and with both.

Studies: --worm-study, CI runs with the facetted worm at SEGMENTS per turn and a STIFFNESS share (the reference's
mesh 0.66x as stiff); --load-study, exact flanks with a driven machine's inertia on the wheel.

    .venv/bin/python studies/reference_facets.py [--slices 16 32] [--samples 400] [--no-dynamic]
    .venv/bin/python studies/reference_facets.py --slices 64 --worm-study --worm 96:1 96:0.66 [--set KEY=VALUE ...]
    .venv/bin/python studies/reference_facets.py --slices 16 --load-study
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path

import mujoco
import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from meshgen import meshes  # noqa: E402
from meshgen import worm as worm_geo  # noqa: E402
from tests.contact3d.test_seeds_pieces import CI  # noqa: E402
from wormsim.contact3d import flank_step  # noqa: E402
from wormsim.contact3d.flank_step import FlankContacts  # noqa: E402
from wormsim.contact3d.mjcf import build_model  # noqa: E402
from wormsim.scenario import load_scenario  # noqa: E402
from wormsim.tooth.grid import flank_grid  # noqa: E402

SCENARIO = ROOT / "scenarios" / "screw_jack.yaml"
REFERENCE_STIFFNESS_SHARE = 0.66  # issue 13: the reference's mesh about 0.66x as stiff as ours


def scenario(slices: int, *extra: str):
    return load_scenario(SCENARIO, [*CI["screw_jack"], "contact.geometry=flanks", f"contact.slices={slices}", *extra])


# ---------------------------------------------------------------- (a) chordal deviation


def tooth0_faces(m: trimesh.Trimesh, g) -> trimesh.Trimesh:
    """The wheel mesh's faces within 0.8 pitch of tooth 0's centre line (polar angle -pi/2 + pi/z2)."""
    c = m.triangles_center
    ang = np.arctan2(c[:, 1], c[:, 0]) - (-math.pi / 2 + math.pi / g.z2)
    ang = (ang + math.pi) % (2 * math.pi) - math.pi
    keep = np.abs(ang) < 0.8 * 2 * math.pi / g.z2
    return m.submesh([np.nonzero(keep)[0]], append=True)


def facet_psi(sub: trimesh.Trimesh, rho, psi, zeta) -> np.ndarray:
    """Polar angle where the circle (rho, ., zeta) through each exact point meets the facetted flank (the hit
    nearest the exact point along the circumferential tangent; the arc's curvature over a few um is negligible)."""
    P = np.stack([rho * np.cos(psi), rho * np.sin(psi), zeta], -1)
    t = np.stack([-np.sin(psi), np.cos(psi), np.zeros_like(psi)], -1)
    out = np.full(len(P), np.nan)
    ray = trimesh.ray.ray_triangle.RayMeshIntersector(sub)
    off = 50e-6  # start 50 um behind the point, both directions checked via one ray spanning +-50 um
    loc, idx, _ = ray.intersects_location(P - off * t, t, multiple_hits=True)
    s = np.einsum("ij,ij->i", loc - P[idx], t[idx])
    best = np.full(len(P), np.inf)
    for i, si in zip(idx, s):
        if abs(si) < abs(best[i]) and abs(si) < off:
            best[i] = si
    ok = np.isfinite(best)
    out[ok] = psi[ok] + best[ok] / rho[ok]
    return out


def wheel_deviation(g, wheel_mesh, slices: int, n_profile: int = 64):
    """Normal deviation (m) of the wheel mesh from the exact flank at tooth 0's grid points, and the facetted psi.
    The facet's polar angle along the circle through the point, rho (psi_facet - psi) (n . e_psi) with the flank
    normal n from the grid's tangents. Sign: + where the facet lies inside the tooth (material removed: gap grows)."""
    gr = flank_grid(g, slices, n_profile)
    sub = tooth0_faces(wheel_mesh, g)
    psi_f = np.full_like(gr.psi, np.nan)
    Z = np.broadcast_to(gr.zeta[:, None], gr.rho.shape)
    for f in range(2):
        ok = np.isfinite(gr.psi[f])
        psi_f[f][ok] = facet_psi(sub, gr.rho[ok], gr.psi[f][ok], Z[ok])
    P = np.stack([gr.rho * np.cos(gr.psi), gr.rho * np.sin(gr.psi), np.broadcast_to(Z, gr.psi.shape)], -1)
    t_prof = np.gradient(P, axis=2)
    t_face = np.gradient(P, axis=1) if slices > 1 else np.zeros_like(P)
    n = np.cross(t_prof, t_face)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    e_psi = np.stack([-np.sin(gr.psi), np.cos(gr.psi), np.zeros_like(gr.psi)], -1)
    cos_n = np.abs(np.einsum("...i,...i", n, e_psi))
    # flank A faces -psi (the tooth lies at larger psi): a facet at larger psi removes material; B mirrored
    sgn = np.array([1.0, -1.0])[:, None, None]
    dev = sgn * gr.rho * (psi_f - gr.psi) * cos_n
    return gr, psi_f, dev


def worm_deviation(g, worm_mesh, n: int = 200_000, seed: int = 0):
    """Normal deviation (m) of points sampled on the worm mesh's flank facets from the exact thread (thread_gap;
    + outside the exact thread: the facet lies inside the material removed, the gap grows), working radii only."""
    pts, _ = trimesh.sample.sample_surface(worm_mesh, n, seed=seed)
    r = np.hypot(pts[:, 0], pts[:, 1])
    gap = worm_geo.thread_gap(g, pts)
    keep = (r > g.r_f1 + 0.2 * g.m_x) & (r < g.r_a1 - 0.05 * g.m_x) & (np.abs(pts[:, 2]) < g.worm_length / 2 - g.p_x)
    keep &= np.abs(gap) < 0.05 * g.m_x  # on a flank (not the tip / root cylinders)
    return r[keep], gap[keep]


# ---------------------------------------------------------------- (b), (c) quasi-static kernel


class QuasiStatic:
    """F_t of the flank kernel with the worm at theta1 and the wheel at the conjugate angle minus a lag."""

    def __init__(self, slices: int, grid=None, worm_facets: bool = False):
        sc = scenario(slices)
        self.worm_facets = worm_facets
        self.bm = build_model(sc)
        self.g = self.bm.geometry
        self.target = sc.load.torque_nm / self.g.r2
        if grid is not None:
            with patched_grid(grid):
                self.fc = FlankContacts(self.bm, slices)
        else:
            self.fc = FlankContacts(self.bm, slices)
        self.d = mujoco.MjData(self.bm.model)

    def f_t(self, th1: float, lag: float) -> float:
        g, fc, d = self.g, self.fc, self.d
        d.qpos[fc.qa1] = th1
        d.qpos[fc.qa2] = g.hand * g.z1 / g.z2 * th1 - g.hand * lag
        n = fc.find(d)
        depth = fc.depth[:n]
        if self.worm_facets:
            depth = np.maximum(depth - worm_facet_recess(g, fc.pos[:n], th1), 0.0)
        f = fc.weight[:n] * self.bm.law.contact_stiffness_n_per_m * depth
        return float((np.cross(fc.pos[:n], fc.nrm[:n])[:, 2] * f).sum() / g.r2)

    def sweep(self, lag, n: int) -> np.ndarray:
        per = 2 * math.pi / self.g.z1
        lag = np.broadcast_to(np.asarray(lag, float), (n,))
        return np.array([self.f_t(per * i / n, lag[i]) for i in range(n)])

    def lag_for_mean(self, n: int = 200) -> float:
        bl = self.g.backlash / (2 * self.g.r2)
        m1, m2 = self.sweep(2 * bl, n).mean(), self.sweep(3 * bl, n).mean()
        lag = 2 * bl + (self.target - m1) / (m2 - m1) * bl
        for _ in range(3):
            m, mb = self.sweep(lag, n).mean(), self.sweep(lag * 1.001, n).mean()
            lag += (self.target - m) / ((mb - m) / (lag * 0.001))
        return lag

    def lag_for_load(self, lag0: float, n: int) -> np.ndarray:
        """Per worm angle, the lag at which F_t carries the load (quasi-static TE under a torque load)."""
        per = 2 * math.pi / self.g.z1
        out = np.empty(n)
        for i in range(n):
            th1, lag = per * i / n, lag0
            for _ in range(30):
                f, fb = self.f_t(th1, lag), self.f_t(th1, lag + 1e-7)
                slope = (fb - f) / 1e-7
                if slope <= 0:
                    lag += 2e-6
                    continue
                step = (self.target - f) / slope
                lag += step
                if abs(step) < 1e-12:
                    break
            out[i] = lag
        return out


WORM_SEGMENTS_PER_TURN = 96  # meshgen.meshes.worm_mesh's default (what worm.stl holds)


def worm_facet_recess(g, pos, th1: float) -> np.ndarray:
    """How far (m, along the flank normal) the worm mesh's facet lies inside the exact thread at assembly points
    `pos` on the worm flank, worm at theta1: the chord between two helix samples dphi apart at radius r lies
    r t (1 - t) dphi^2 / 2 inside the cylinder (t = the point's share of the way between the samples), which the
    flank normal sees times |n . e_r| = |H'| / sqrt(1 + (p/r)^2 + H'^2). Matches (a)'s sampled deviation within 4 %
    (2.67 um measured, 2.76 um by this at r_a1 - 0.05 m_x). The samples' phase (worm_mesh's phi0) only shifts the
    pattern: taken 0."""
    xs, ys = pos[:, 1] + g.a, -pos[:, 2]  # static worm frame (meshgen.assembly: x_s = y + a, y_s = -z)
    r = np.hypot(xs, ys)
    dphi = 2 * math.pi / WORM_SEGMENTS_PER_TURN
    t = np.mod((np.arctan2(ys, xs) - th1) / dphi, 1.0)
    hp = worm_geo.half_thickness_dr(g, r)
    return r * t * (1 - t) * dphi**2 / 2 * np.abs(hp) / np.sqrt(1 + (g.p / r) ** 2 + hp**2)


class patched_grid:
    """flank_step.flank_grid replaced by one returning `grid` (FlankContacts and the compiled loop read its arrays)."""

    def __init__(self, grid):
        self.grid = grid

    def __enter__(self):
        self.old = flank_step.flank_grid
        flank_step.flank_grid = lambda g, slices, *a, **k: self.grid
        return self

    def __exit__(self, *exc):
        flank_step.flank_grid = self.old


class worm_facet_kernel:
    """The flank kernel (flanks.find_packed) and the compiled step loop (flank_loop) rebuilt from their source with the
    worm's facets in worm_gap_ext: the gap grows by the facet's recess of worm_facet_recess (the same closed form), so
    a dynamic run sees the STL's worm. The modified copies are written to `folder` and imported from there."""

    HOOK = "    return (abs(u) - H) * inrm, ex\n"

    def __init__(self, folder: Path, segments_per_turn: int = WORM_SEGMENTS_PER_TURN):
        self.folder = Path(folder)
        self.segments = segments_per_turn

    def __enter__(self):
        import importlib

        from wormsim.contact3d import flank_loop
        from wormsim.tooth import gap, kernel

        self.folder.mkdir(parents=True, exist_ok=True)
        src = Path(gap.__file__).read_text()
        assert src.count(self.HOOK) == 1, "gap.worm_gap_ext changed: update worm_facet_kernel.HOOK"
        dphi = 2 * math.pi / self.segments
        src = src.replace(
            self.HOOK,
            f"    t = (phi - theta1) / {dphi!r}\n"
            "    t -= math.floor(t)\n"
            f"    return (abs(u) - H + r * t * (1.0 - t) * {dphi**2 / 2!r} * abs(dH)) * inrm, ex\n",
        )
        name = f"facet_flanks_{self.segments}"
        (self.folder / f"{name}_gap.py").write_text(src)
        ksrc = Path(kernel.__file__).read_text().replace("from wormsim.tooth.gap import", f"from {name}_gap import")
        (self.folder / f"{name}.py").write_text(ksrc)
        lsrc = Path(flank_loop.__file__).read_text()
        old = "from wormsim.tooth.kernel import find_packed"
        assert old in lsrc
        (self.folder / f"{name}_loop.py").write_text(lsrc.replace(old, f"from {name} import find_packed"))
        sys.path.insert(0, str(self.folder))
        self.names = (name, f"{name}_loop")
        ff, fl = (importlib.import_module(n) for n in self.names)
        self.saved = (flank_step.find_packed, sys.modules["wormsim.contact3d.flank_loop"])
        flank_step.find_packed = ff.find_packed
        sys.modules["wormsim.contact3d.flank_loop"] = fl
        return self

    def __exit__(self, *exc):
        flank_step.find_packed, sys.modules["wormsim.contact3d.flank_loop"] = self.saved
        sys.path.remove(str(self.folder))
        for n in self.names:
            sys.modules.pop(n, None)


def facetted_grid(gr, psi_f):
    """The exact grid with the wheel flank's polar angles taken from the facets (c unchanged: the conjugate angle
    only orders the candidates; the gap is evaluated at the facetted point)."""
    ok = np.isfinite(psi_f)
    psi = np.where(ok, psi_f, gr.psi)
    xy = np.stack([gr.rho * np.cos(psi), gr.rho * np.sin(psi)], axis=-1)
    return dataclasses.replace(gr, psi=psi, xy=xy)


def dynamic(slices: int, grid=None, worm_facets: int = 0, *extra: str) -> dict:
    """The screw jack's CI run with flanks at `slices`; grid: the wheel's flank grid replaced; worm_facets: the worm's
    facets at that many segments per turn (0: exact worm); extra: scenario overrides."""
    import contextlib
    import tempfile

    from wormsim.contact3d.runner import simulate

    sc = scenario(slices, *extra)
    with contextlib.ExitStack() as st:
        if grid is not None:
            st.enter_context(patched_grid(grid))
        if worm_facets:
            folder = Path(st.enter_context(tempfile.TemporaryDirectory()))
            st.enter_context(worm_facet_kernel(folder, worm_facets))
        return simulate(sc).summary


def worm_study(slices: int, cases, with_wheel: bool = False, *extra: str) -> None:
    """F_t p2p of CI runs with the facetted worm against its segments per turn (the recess ~ 1 / segments^2) and
    the contact stiffness (1x, and the reference's 0.66x); SEGMENTS 0: the exact worm; with_wheel: the wheel's
    facets too (facetted_grid)."""
    g = build_model(scenario(slices)).geometry
    K = scenario(slices).contact.stiffness_n_per_m
    hp = float(worm_geo.half_thickness_dr(g, g.r_a1))
    n_r = abs(hp) / math.sqrt(1 + (g.p / g.r_a1) ** 2 + hp**2)
    grid = None
    if with_wheel:
        gr, psi_f, _ = wheel_deviation(g, meshes.wheel_mesh(g), slices)
        grid = facetted_grid(gr, psi_f)
    for seg, share in cases:
        sm = dynamic(slices, grid, seg, f"contact.stiffness_n_per_m={K * share}", *extra)
        rec = g.r_a1 * (2 * math.pi / seg) ** 2 / 8 * n_r if seg else 0.0
        print(
            f"{slices} slices, h {sm['timestep_s']} s, wheel facets {with_wheel}: worm facets {seg}/turn (recess "
            f"max ~{rec * 1e6:.2f} um at r_a1), stiffness {share}x: F_t mean "
            f"{sm['tangential_force_mean_n']:.1f} N, p2p {sm['tangential_force_p2p_n']:.2f} N, TE p2p "
            f"{sm['transmission_error_p2p_urad']:.2f} urad, F_t peak {sm['mesh_frequency_hz']:.2f} Hz",
            flush=True,
        )


def held_study(slices: int, n: int = 240) -> None:
    """The facetted worm (first order, quasi-static) with the wheel held at the lag that carries the load on the cycle's
    mean: F_t over two worm facets (7.5 deg of worm turn, where the wheel cannot follow: 2128 Hz against the mesh
    mode) at three places in the mesh cycle. The p2p within such a window is the facets' ripple for a held wheel;
    its change with the slices shows the slices' sampling of the pattern along the contact line."""
    wf = QuasiStatic(slices, worm_facets=True)
    lag = wf.lag_for_mean()
    dphi = 2 * math.pi / WORM_SEGMENTS_PER_TURN
    out = []
    for th0 in (0.0, 2.1, 4.2):
        F = np.array([wf.f_t(th0 + 2 * dphi * i / n, lag) for i in range(n)])
        out.append(f"{np.ptp(F):.1f}")
    print(f"held wheel, {slices} slices: F_t p2p over two worm facets {' / '.join(out)} N", flush=True)


def load_study(slices: int) -> None:
    """Exact flanks, the wheel's load with a driven-machine inertia (load.inertia_kg_m2; the bare wheel's J2 is
    about 2.4e-4 kg m^2): a heavier wheel side lowers the mesh mode towards the meshing harmonics."""
    for inertia in (0.0, 2.4e-3, 2.4e-2):
        sm = dynamic(slices, None, 0, f"load.inertia_kg_m2={inertia}")
        print(
            f"exact flanks, load inertia {inertia} kg m^2: F_t mean {sm['tangential_force_mean_n']:.1f} N, p2p "
            f"{sm['tangential_force_p2p_n']:.2f} N, TE p2p {sm['transmission_error_p2p_urad']:.2f} urad, F_t peak "
            f"{sm['mesh_frequency_hz']:.2f} Hz, steady window {sm['steady_window_s']}",
            flush=True,
        )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--slices", type=int, nargs="+", default=[16, 64])
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--no-dynamic", action="store_true")
    ap.add_argument("--worm-study", action="store_true", help="only the facetted worm against segments and stiffness")
    ap.add_argument("--load-study", action="store_true", help="only exact flanks against the load's inertia")
    ap.add_argument("--worm", nargs="+", default=["96:1", "96:0.66", "192:1", "384:1"], help="SEGMENTS:STIFFNESS")
    ap.add_argument("--set", nargs="*", default=[], help="scenario overrides for --worm-study")
    ap.add_argument("--with-wheel", action="store_true", help="--worm-study with the wheel's facets too")
    ap.add_argument("--held-study", action="store_true", help="only the facetted worm with the wheel held")
    a = ap.parse_args()
    if a.held_study:
        for s in a.slices:
            held_study(s)
        return
    if a.load_study:
        for s in a.slices:
            load_study(s)
        return
    if a.worm_study:
        cases = [(int(c.split(":")[0]), float(c.split(":")[1])) for c in a.worm]
        for s in a.slices:
            worm_study(s, cases, a.with_wheel, *a.set)
        return
    g = build_model(scenario(16)).geometry
    wm, gm = meshes.wheel_mesh(g), meshes.worm_mesh(g)
    print(f"wheel mesh {len(wm.faces)} faces, worm mesh {len(gm.faces)} faces")
    r, gap = worm_deviation(g, gm)
    print(
        f"(a) worm flank facets vs exact thread: {len(r)} points, deviation max {gap.max() * 1e6:.3f} um, "
        f"min {gap.min() * 1e6:.3f} um, mean {gap.mean() * 1e6:.3f} um, rms {np.sqrt((gap**2).mean()) * 1e6:.3f} um"
    )
    for s in a.slices:
        gr, psi_f, dev = wheel_deviation(g, wm, s)
        v = dev[np.isfinite(dev)]
        print(
            f"(a) wheel flank (tooth 0, {s} slices x 64 profile points, active flank): deviation max "
            f"{v.max() * 1e6:.3f} um, min {v.min() * 1e6:.3f} um, mean {v.mean() * 1e6:.3f} um, "
            f"rms {np.sqrt((v**2).mean()) * 1e6:.3f} um; facet psi found for {np.isfinite(psi_f).sum()} of "
            f"{np.isfinite(gr.psi).sum()} points"
        )
        ex, fa = QuasiStatic(s), QuasiStatic(s, facetted_grid(gr, psi_f))
        lag = ex.lag_for_mean()
        F = ex.sweep(lag, a.samples)
        dl = 1e-3 * lag
        k_mesh = (ex.sweep(lag + dl, 200).mean() - ex.sweep(lag, 200).mean()) / (g.r2 * dl)
        defl = F.mean() / k_mesh
        print(
            f"(b) {s} slices: exact flanks at the fixed lag {lag * 1e6:.2f} urad: F_t mean {F.mean():.1f} N, "
            f"p2p {np.ptp(F):.1f} N; k_mesh = dF_t/d(r2 lag) {k_mesh:.4g} N/m (mean deflection beyond the backlash "
            f"{defl * 1e6:.3f} um); k_mesh x worm facet p2p {k_mesh * np.ptp(gap):.0f} N "
            f"({REFERENCE_STIFFNESS_SHARE}x: {REFERENCE_STIFFNESS_SHARE * k_mesh * np.ptp(gap):.0f} N), "
            f"x wheel facet p2p {k_mesh * np.ptp(v):.0f} N ({REFERENCE_STIFFNESS_SHARE * k_mesh * np.ptp(v):.0f} N)"
        )
        Ff = fa.sweep(lag, a.samples)
        lag_f = fa.lag_for_mean()
        Ff2 = fa.sweep(lag_f, a.samples)
        print(
            f"(c) {s} slices: facetted wheel at the same lag: F_t mean {Ff.mean():.1f} N, p2p {np.ptp(Ff):.1f} N; "
            f"at its own lag {lag_f * 1e6:.2f} urad: mean {Ff2.mean():.1f} N, p2p {np.ptp(Ff2):.1f} N"
        )
        wf = QuasiStatic(s, worm_facets=True)
        Fw = wf.sweep(lag, a.samples)
        lag_w = wf.lag_for_mean()
        Fw2 = wf.sweep(lag_w, a.samples)
        print(
            f"(c) {s} slices: facetted worm (first order: each contact's depth less the facet's recess) at the exact "
            f"lag: F_t mean {Fw.mean():.1f} N, p2p {np.ptp(Fw):.1f} N; at its own lag {lag_w * 1e6:.2f} urad: mean "
            f"{Fw2.mean():.1f} N, p2p {np.ptp(Fw2):.1f} N"
        )
        n_te = max(200, a.samples // 4)
        te_e = ex.lag_for_load(lag, n_te)
        te_f = fa.lag_for_load(lag_f, n_te)
        te_w = wf.lag_for_load(lag_w, n_te)
        print(
            f"(c) {s} slices: quasi-static TE at the load ({n_te} angles): exact p2p {np.ptp(te_e) * 1e6:.2f} urad, "
            f"facetted wheel {np.ptp(te_f) * 1e6:.2f} urad, facetted worm {np.ptp(te_w) * 1e6:.2f} urad (x r2: "
            f"{np.ptp(te_e) * g.r2 * 1e6:.3f} / {np.ptp(te_f) * g.r2 * 1e6:.3f} / {np.ptp(te_w) * g.r2 * 1e6:.3f} um)"
        )
        if not a.no_dynamic:
            fg = facetted_grid(gr, psi_f)
            W = WORM_SEGMENTS_PER_TURN
            cases = (("exact", None, 0), ("facetted wheel", fg, 0), ("facetted worm", None, W))
            cases += (("facetted worm and wheel", fg, W),)
            for name, grid, wfac in cases:
                sm = dynamic(s, grid, wfac)
                print(
                    f"(c) {s} slices CI run, {name}: F_t mean {sm['tangential_force_mean_n']:.1f} N, p2p "
                    f"{sm['tangential_force_p2p_n']:.2f} N, TE p2p {sm['transmission_error_p2p_urad']:.2f} urad, "
                    f"F_t peak {sm['mesh_frequency_hz']:.2f} Hz"
                )


if __name__ == "__main__":
    main()
