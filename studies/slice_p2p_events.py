"""Where in time F_t's p2p sits, and what rings (issue 31, item 2; docs/contact3d.md, "Default slice count"): one case
of studies/slice_convergence_default.py (medium) at several slice counts, optionally at another worm speed or timestep,
one sample per step. Per run: F_t p2p over the steady window (whole, below BAND_HZ), the times of its largest and
smallest value and their phase in the mesh cycle (t f_mesh mod 1, f_mesh = z1 n1 / 60), the teeth in contact and
F_t at the steps around the largest value (an entry or an exit shows as a change of the teeth in contact), the
ringing's frequency (zero crossings of F_t above BAND_HZ in the 3 ms after the largest value), the p2p per mesh cycle
and the largest lines of F_t's spectrum.

    .venv/bin/python studies/slice_p2p_events.py [--case left-q6-4start] [--slices 32 64 128] [--speed RPM]
        [--step S] [--n-profile N] [--record NAME]

--n-profile N: the flank grid's points along the profile (wormsim.tooth.grid.N_PROFILE) for a study of the profile's
resolution (docs/decisions/0060-128-profile-points.md).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studies.slice_convergence_default import BAND_HZ, scenario  # noqa: E402
from wormsim.contact3d.runner import simulate  # noqa: E402
from wormsim.results.metrics import p2p_below  # noqa: E402
from wormsim.results.provenance import record  # noqa: E402
from wormsim.scenario import Scenario  # noqa: E402


def run(case: str, slices: int, speed_rpm: float | None, timestep_s: float | None) -> dict:
    """The case at `slices` (and speed / step), one sample per step; the measures of the module docstring."""
    d = scenario(case, slices, medium=True).model_dump()
    d["simulation"]["record_every"] = 1
    if speed_rpm is not None:
        d["drive"]["speed_rpm"] = speed_rpm
    if timestep_s is not None:
        d["simulation"]["timestep_s"] = timestep_s
    sc = Scenario.model_validate(d)
    t0 = time.process_time()
    res = simulate(sc)
    cpu = time.process_time() - t0
    r, S = res.summary, res.series
    t, f = S["t_s"], S["tangential_force_n"]
    w = r["steady_window_s"]
    m = (t >= w[0]) & (t <= w[1])
    tt, ff, teeth = t[m], f[m], S["teeth_in_contact"][m]
    f_mesh = sc.gear.worm_starts * sc.drive.speed_rpm / 60.0
    dt = float(tt[1] - tt[0])
    spec = np.fft.rfft(ff - ff.mean())
    fr = np.fft.rfftfreq(len(ff), dt)
    hp = np.fft.irfft(np.where(fr > BAND_HZ, spec, 0), len(ff))
    i_hi, i_lo = int(np.argmax(ff)), int(np.argmin(ff))
    after = (tt > tt[i_hi]) & (tt < tt[i_hi] + 3e-3)
    zc = np.nonzero(np.diff(np.sign(hp[after])) != 0)[0]
    ring_hz = float(1.0 / (2.0 * np.median(np.diff(tt[after][zc])))) if len(zc) > 2 else None
    cyc = np.floor(tt * f_mesh).astype(int)
    amp = np.abs(spec) * 2 / len(ff)
    top = np.argsort(amp)[::-1][:8]
    return {
        "slices": r["flank_slices"],
        "speed_rpm": sc.drive.speed_rpm,
        "timestep_s": r["timestep_s"],
        "f_mesh_hz": f_mesh,
        "ft_mean_n": r["tangential_force_mean_n"],
        "ft_p2p_n": r["tangential_force_p2p_n"],
        "ft_p2p_band_n": float(p2p_below(tt, ff, BAND_HZ)),
        "ft_p2p_above_band_n": float(np.ptp(hp)),
        "ph_max_mpa": r.get("contact_pressure_max_mpa"),
        "max_t_s": float(tt[i_hi]),
        "max_phase": float((tt[i_hi] * f_mesh) % 1.0),
        "min_t_s": float(tt[i_lo]),
        "min_phase": float((tt[i_lo] * f_mesh) % 1.0),
        "teeth_around_max": [int(v) for v in teeth[max(i_hi - 3, 0) : i_hi + 4]],
        "ft_around_max_n": [float(v) for v in ff[max(i_hi - 3, 0) : i_hi + 4]],
        "ringing_hz": ring_hz,
        "p2p_per_cycle_n": [float(np.ptp(ff[cyc == c])) for c in np.unique(cyc) if (cyc == c).sum() > 10],
        "spectrum_lines": [[float(fr[i]), float(amp[i])] for i in sorted(top)],
        "cpu_s": cpu,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", default="left-q6-4start")
    ap.add_argument("--slices", type=int, nargs="+", default=[32, 64, 128])
    ap.add_argument("--speed", type=float, help="worm speed, rpm (default: the case's)")
    ap.add_argument("--step", type=float, help="timestep, s (default: the case's)")
    ap.add_argument("--record")
    ap.add_argument("--n-profile", type=int, help="points along the profile (default: wormsim.tooth.grid.N_PROFILE)")
    a = ap.parse_args()
    if a.n_profile is not None:  # a study of the profile's resolution (grid.flank_grid reads it when called)
        from wormsim.tooth import grid

        grid.N_PROFILE = a.n_profile
    from wormsim.tooth.grid import N_PROFILE

    out: dict = {"case": a.case, "band_hz": BAND_HZ, "speed_rpm": a.speed, "timestep_s": a.step, "n_profile": N_PROFILE}
    out["runs"] = []
    for S in a.slices:
        r = run(a.case, S, a.speed, a.step)
        out["runs"].append(r)
        print(
            S,
            {k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items() if k not in ("spectrum_lines",)},
            flush=True,
        )
        if a.record:
            record(a.record, out)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
