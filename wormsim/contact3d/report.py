"""report.png and recording.rrd of a contact3d run.

report.png: tooth forces on the wheel (tangential, radial, axial) with the steady window shaded; shaft
speeds; the FFT amplitude spectrum of the tangential force over the steady window with the theoretical
meshing frequency marked; the contact pattern on a wheel tooth (contact points of the steady window,
mapped into the frame of tooth 0: axial position across the face against radius, coloured by force).

recording.rrd (wormsim.results.recording layout): /series/* time series on the sim_time timeline; the worm and
wheel meshes under /assembly/worm and /assembly/wheel moved by their 4x4 transforms; contact points
(/assembly/contacts/points) and force arrows on the wheel (/assembly/contacts/forces, 1 mm per
`ARROW_N_PER_MM` newtons) at up to MAX_FRAMES instants. With exact flanks: the steady-window contact
pattern on every wheel tooth, coloured by pressure (/assembly/wheel/contact_pattern, wormsim.tooth.hertz.log_pattern),
and in report.png the pattern as a band on the wheel flank coloured by pressure (wormsim.tooth.hertz.draw_pattern).
Below: the mesh stiffness k(theta1) and the load share of each wheel tooth (wormsim.tooth.stiffness_plot).
"""

from __future__ import annotations

import numpy as np

from meshgen import assembly
from wormsim.contact3d.mjcf import visual_vertex_normals
from wormsim.results.metrics import dominant_frequency
from wormsim.results.recording import log_mesh, log_series, log_transforms, recording
from wormsim.results.report_header import (
    draw_header,
    gear_line,
    header_rows,
    results_line,
    shafts_line,
    speed_ylim,
    steady_ylim,
    warning_text,
)
from wormsim.results.result import Result

MAX_FRAMES = 1500
ARROW_N_PER_MM = None  # chosen per run: the mean tooth force maps to 5 mm


SPEED_INTERVALS = 40  # the speeds panel shows the means over this many equal intervals of the run


def _interval_means(t: np.ndarray, *ys: np.ndarray, n: int):
    """Means of each y over n equal time intervals, at the interval centres."""
    edges = np.linspace(t[0], t[-1], n + 1)
    idx = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, n - 1)
    count = np.bincount(idx, minlength=n)
    keep = count > 0
    centres = 0.5 * (edges[:-1] + edges[1:])[keep]
    return (centres, *[(np.bincount(idx, weights=y, minlength=n)[keep] / count[keep]) for y in ys])


def write_report(result: Result, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    S, s = result.series, result.summary
    t = S["t_s"]
    w0, w1 = s["steady_window_s"]
    sl = (t >= w0) & (t <= w1)
    geo = result.extra["built"].geometry
    scaled = s.get("mass_scaling", 1) > 1  # wormsim.contact3d.mass_scaling: say so where the plots are
    lines = [gear_line(geo), shafts_line(s), results_line(s, geo)]
    warn = warning_text(
        s,
        f"MASS SCALING x {s['mass_scaling']:g} (kinetic energy {100 * s['kinetic_energy_share']:.2g} % "
        f"of the work): means only; force fluctuation, speeds' rattle and start-up peaks are not physical"
        if scaled
        else "",
    )
    hh = header_rows(lines, warn)
    ms = result.extra.get("mesh_stiffness")
    rows = [hh, 4.4, 4.4] + ([4.4] if ms is not None else [])
    fig = plt.figure(figsize=(13, sum(rows)))
    gs = fig.add_gridspec(len(rows), 2, height_ratios=rows)
    ax = np.array([[fig.add_subplot(gs[i, j]) for j in range(2)] for i in (1, 2)])
    draw_header(
        fig.add_subplot(gs[0, :]),
        lines,
        f"{s.get('scenario', '')} (contact3d): dt {s['timestep_s']:.3g} s, resolution {s['resolution']}, "
        f"contacts {s.get('contact_geometry', '')}, steady window {w0:.3g}-{w1:.3g} s",
        warn=warn,
    )
    _draw_forces(ax[0, 0], S, s)
    _draw_speeds(ax[0, 1], S, s)
    _draw_spectrum(ax[1, 0], S, s, sl)
    _draw_pattern(ax[1, 1], fig, result, sl)
    if ms is not None:  # the tooth pair's stiffness and load shares (wormsim.tooth.stiffness_plot), as at torsional
        from wormsim.tooth.stiffness_plot import draw_load_shares, draw_mesh_stiffness

        draw_mesh_stiffness(fig.add_subplot(gs[3, 0]), ms, result.extra.get("ltca"))
        draw_load_shares(fig.add_subplot(gs[3, 1]), result.extra.get("ltca"), ms.stiffness_source)
    fig.tight_layout()
    fig.set_layout_engine(None)  # tight_layout leaves a placeholder engine: savefig would draw twice
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _draw_forces(a, S: dict, s: dict) -> None:
    """The tooth forces on the wheel against time, the axes fitted to the steady window."""
    t = S["t_s"]
    w0, w1 = s["steady_window_s"]
    forces = [S[k] for k in ("tangential_force_n", "radial_force_n", "axial_force_n")]
    for y, lab in zip(forces, ("tangential", "radial", "axial"), strict=True):
        a.plot(t, y, lw=0.6, label=lab)
    a.axvspan(w0, w1, color="0.9", zorder=-1, label="steady window")
    if np.isfinite(s.get("tangential_force_theory_n", float("nan"))):
        a.axhline(s["tangential_force_theory_n"], color="k", ls="--", lw=0.8, label="T_load / r2")
    lo, hi = steady_ylim(t, forces, (w0, w1), pad=0.15)
    a.set_ylim(lo, hi)
    peak = s.get("startup_tangential_force_peak_n")
    if peak is not None and np.isfinite(peak):
        off = " (off scale)" if peak > hi else ""
        a.plot([], [], " ", label=f"start-up peak F_t {peak:.4g} N{off}")
    a.set(xlabel="time [s]", ylabel="force on the wheel [N]", title="tooth forces on the wheel (axes: steady window)")
    a.legend(fontsize=7, loc="best")


def _draw_speeds(a, S: dict, s: dict) -> None:
    """The wheel's and the worm's (over the ratio) speeds: raw traces faint (the wheel rattles at the contact
    frequencies and would hide the worm), interval means bold."""
    t = S["t_s"]
    w0, w1 = s["steady_window_s"]
    worm, wheel = np.abs(S["worm_speed_rpm"]) / s["ratio_theory"], np.abs(S["wheel_speed_rpm"])
    tm, worm_m, wheel_m = _interval_means(t, worm, wheel, n=SPEED_INTERVALS)
    a.plot(t, wheel, lw=0.4, color="C1", alpha=0.25)
    a.plot(t, worm, lw=0.4, color="C0", alpha=0.25)
    a.plot(
        tm, wheel_m, "-", color="C1", lw=1.6, label=f"wheel (mean of {t[-1] / SPEED_INTERVALS * 1e3:.3g} ms intervals)"
    )
    a.plot(tm, worm_m, "--", color="C0", lw=1.6, label="worm / (z2/z1) (interval means)")
    a.axvspan(w0, w1, color="0.9", zorder=-1)
    a.set_ylim(*speed_ylim(tm, [worm_m, wheel_m], (w0, w1)))  # the raw rattle and start-up are clipped
    a.set(
        xlabel="time [s]",
        ylabel="wheel speed [rpm] (raw traces faint, clipped)",
        title=f"speeds: wheel {s['wheel_speed_mean_rpm']:.4g} rpm, worm {s['worm_speed_mean_rpm']:.4g} rpm "
        f"(ratio {s['ratio']:.5g})",
    )
    a.legend(fontsize=8, loc="lower right")


def _draw_spectrum(a, S: dict, s: dict, sl) -> None:
    """The tangential force's spectrum over the steady window (sl) with the theory's and the found meshing line."""
    _, df, fr, sp = dominant_frequency(S["t_s"][sl], S["tangential_force_n"][sl])
    if len(fr):
        a.semilogy(fr[1:], np.maximum(sp[1:], 1e-9), lw=0.7)
        a.axvline(
            s["mesh_frequency_theory_hz"],
            color="r",
            ls="--",
            lw=0.8,
            label=f"z1 n1/60 = {s['mesh_frequency_theory_hz']:.4g} Hz",
        )
        a.axvline(
            s["mesh_frequency_hz"],
            color="g",
            ls=":",
            lw=1.0,
            label=f"peak {s['mesh_frequency_hz']:.4g} Hz (bin {df:.3g} Hz)",
        )
        # up to the 10th meshing harmonic, and past the reported peak wherever it lies
        a.set_xlim(0, min(fr[-1], max(10 * max(s["mesh_frequency_theory_hz"], df), 1.2 * s["mesh_frequency_hz"])))
    a.set(xlabel="frequency [Hz]", ylabel="|F_t| amplitude [N]", title="spectrum of the tangential force (Hann)")
    a.legend(fontsize=8)


def _draw_pattern(a, fig, result: Result, sl) -> None:
    """The contact pattern on a wheel tooth over the steady window (sl): the exact flanks' loaded band coloured by
    pressure (wormsim.tooth.hertz), or the pieces' contact points coloured by force."""
    s = result.summary
    geo = result.extra["built"].geometry
    P = result.extra.get("points_tooth0")
    F = result.extra.get("forces_world")
    if "flank_pattern" in result.extra:
        from wormsim.tooth.hertz import draw_pattern

        draw_pattern(a, fig, result.extra["flank_pattern"], result.extra["built"].geometry, s)
    elif P is not None and sl.any():
        p = P[sl].reshape(-1, 3)
        f = np.linalg.norm(F[sl].reshape(-1, 3), axis=1)
        ok = np.isfinite(p[:, 0])
        r = np.hypot(p[ok, 0], p[ok, 1]) * 1e3
        sc = a.scatter(p[ok, 2] * 1e3, r, c=f[ok], s=3, cmap="viridis")
        fig.colorbar(sc, ax=a, label="contact force [N]")
        from wormsim.tooth.hertz import draw_tooth_outline

        draw_tooth_outline(a, geo)
        a.set_xlim(-0.6 * geo.face_width * 1e3, 1.15 * geo.face_width * 1e3)
        rr = r if len(r) else np.array([geo.r2 * 1e3])
        lo, hi = min(geo.r_f2 * 1e3, float(rr.min())), max(geo.r_e2 * 1e3, float(rr.max()))
        a.set_ylim(lo - 0.15 * (hi - lo), hi + 0.1 * (hi - lo))
        a.set(xlabel="across the face (wheel z) [mm]", ylabel="radius [mm]", title="contact pattern on a wheel tooth")


def write_recording(result: Result, path) -> None:
    import rerun as rr

    bm = result.extra["built"]
    geo = bm.geometry
    S = result.series
    t = S["t_s"]
    gs = bm.pieces
    normals = {part: visual_vertex_normals(gs, f"{part}_visual") for part in ("worm", "wheel")}  # cached (mjcf)
    with recording(path, f"contact3d-{result.summary.get('scenario', 'run')}") as rec:
        log_series(rec, t, {k: v for k, v in S.items() if k != "drive_command"})
        for part, color in (("worm", (150, 160, 180)), ("wheel", (220, 165, 80))):
            mesh = getattr(gs, f"{part}_visual")
            log_mesh(rec, f"assembly/{part}/mesh", mesh.vertices, mesh.faces, color, vertex_normals=normals[part])
        idx = np.unique(np.linspace(0, len(t) - 1, min(len(t), MAX_FRAMES)).astype(int))
        Tw = np.stack([assembly.worm_to_assembly(float(a), geo) for a in S["worm_angle_rad"][idx]])
        Tg = np.stack([assembly.wheel_to_assembly(float(a)) for a in S["wheel_angle_rad"][idx]])
        log_transforms(rec, "assembly/worm", t[idx], Tw)
        log_transforms(rec, "assembly/wheel", t[idx], Tg)
        if "flank_pattern" in result.extra:  # exact flanks: the loaded pattern on the wheel, coloured by pressure
            from wormsim.tooth.hertz import log_pattern

            log_pattern(rec, "assembly/wheel/contact_pattern", result.extra["flank_pattern"], geo)
        P, F = result.extra["points_world"], result.extra["forces_world"]
        fmean = np.nanmean(np.linalg.norm(F.reshape(-1, 3), axis=1)) if np.isfinite(F).any() else 1.0
        scale = 5e-3 / max(fmean, 1e-9)  # mean contact force -> 5 mm arrow
        # one send_columns per entity (rows of varying length: partition), not one archetype per instant
        Pi, Fi = P[idx], F[idx]
        ok = np.isfinite(Pi[:, :, 0])
        lengths = ok.sum(axis=1)
        # nanoseconds rounded as rr.set_time rounds them (TimeColumn of float seconds truncates)
        times = [rr.TimeColumn("sim_time", duration=np.round(1e9 * t[idx]).astype(np.int64).astype("timedelta64[ns]"))]
        n = len(idx)
        rr.send_columns(
            "assembly/contacts/points",
            indexes=times,
            columns=[
                *rr.Points3D.columns(positions=Pi[ok]).partition(lengths),
                *rr.Points3D.columns(radii=np.full(n, 2e-4), colors=np.tile((230, 40, 40), (n, 1))),
            ],
            recording=rec,
        )
        rr.send_columns(
            "assembly/contacts/forces",
            indexes=times,
            columns=[
                *rr.Arrows3D.columns(origins=Pi[ok], vectors=Fi[ok] * scale).partition(lengths),
                *rr.Arrows3D.columns(colors=np.tile((40, 200, 40), (n, 1))),
            ],
            recording=rec,
        )
