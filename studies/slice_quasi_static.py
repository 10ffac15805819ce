"""The mesh stiffness the kernel gives at S slices against 2 S, without MuJoCo (issue 31, item 2; docs/contact3d.md,
"Default slice count"): a case of studies/slice_convergence_default.py, the rigid conjugate pose held back by the
backlash angle and a small approach, swept over one mesh cycle; per sample each window tooth's load per unit of the
tooth pair's stiffness K (sum of w delta / S over its loaded flank's contacts: kernel.find_packed's weights and depths,
tests/tooth/test_kernel.py's mesh_sweep) and the mesh's k(theta) / K (their sum over the approach). From k(theta)
the contact mode's response to it (the dynamic mesh force of a one-degree-of-freedom mesh, F0 kappa / k_mean
r^2 / (1 - r^2 + 2 i zeta r), r = f / f_n, f_n = sqrt(k_mean / m_eff) / 2 pi; decision 0045's hand estimate): its p2p
at S and 2 S.

    .venv/bin/python studies/slice_quasi_static.py --cases screw_jack ZA-a25-z60-3start [--slices 16 32 64]
        [--samples 2048] [--n-profile N] [--record NAME]

--n-profile N: the flank grid's points along the profile (wormsim.tooth.grid.N_PROFILE). The record also holds the
mesh stiffness's harmonics 14-17 (share of its mean) per count.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studies.slice_convergence_default import scenario  # noqa: E402
from tests.tooth.test_kernel import APPROACH_M  # noqa: E402
from tests.tooth.test_kernel import mesh_sweep as sweep  # noqa: E402
from wormsim.contact3d.mjcf import flank_slices, prepare  # noqa: E402
from wormsim.results.provenance import record  # noqa: E402


def mode_response(kappa: np.ndarray, f_mesh_hz: float, f_n_hz: float, zeta: float) -> np.ndarray:
    """The dynamic mesh force per unit mean force of k(theta) / k_mean - 1 = kappa sampled over one mesh cycle
    (periodic): each harmonic n times r^2 / (1 - r^2 + 2 i zeta r), r = n f_mesh / f_n, added to the quasi-static
    part (the force itself is constant quasi-statically)."""
    spec = np.fft.rfft(kappa)
    r = np.arange(len(spec)) * f_mesh_hz / f_n_hz
    h = r**2 / (1 - r**2 + 2j * zeta * r)
    return np.fft.irfft(spec * h, len(kappa))


def case(name: str, slices: list[int] | None, samples: int) -> dict:
    sc = scenario(name, None, medium=True)
    p = prepare(sc)
    g = p.geometry
    s0 = flank_slices(sc, g)
    counts = slices or [s0, 2 * s0, 4 * s0]
    K = p.law.pair_stiffness_n_per_m
    m_eff = p.law.effective_mass_kg
    zeta = p.law.contact_damping_n_s_per_m * p.law.contacts_per_pair / (2 * math.sqrt(K * m_eff))
    f_mesh = g.z1 * sc.drive.speed_rpm / 60.0
    out: dict = {"default_slices": s0, "counts": counts, "f_mesh_hz": f_mesh, "zeta": zeta, "runs": {}}
    ref = None
    for S in reversed(counts):  # the finest first: the others against it
        t0 = time.process_time()
        r = sweep(g, S, samples)
        cpu = time.process_time() - t0
        k = r["k_mesh"] * K
        f_n = math.sqrt(k.mean() / m_eff) / (2 * math.pi)
        kappa = k / k.mean() - 1
        dyn = mode_response(kappa, f_mesh, f_n, zeta)
        run = {
            "k_mean_n_per_m": float(k.mean()),
            "k_p2p_share": float(np.ptp(k) / k.mean()),
            "f_n_hz": f_n,
            "dyn_p2p_share": float(np.ptp(dyn)),
            "k_harmonics_14_17_share": [float(v) for v in np.abs(np.fft.rfft(kappa))[14:18] * 2 / len(kappa)],
            "cpu_s": cpu,
        }
        if ref is None:
            ref = r
        else:
            run["k_max_dev_vs_finest"] = float(np.abs(r["k_mesh"] - ref["k_mesh"]).max() / ref["k_mesh"].mean())
            run["tooth_max_dev_vs_finest"] = max(
                float(np.abs(v - ref["loads"][kk]).max() / ref["loads"][kk].max())
                for kk, v in r["loads"].items()
                if kk in ref["loads"] and ref["loads"][kk].max() > 0
            )
        out["runs"][str(S)] = run
        print(name, S, {a: round(b, 5) if isinstance(b, float) else b for a, b in run.items()}, flush=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="+", default=["screw_jack"])
    ap.add_argument("--slices", type=int, nargs="+")
    ap.add_argument("--samples", type=int, default=2048)
    ap.add_argument("--record")
    ap.add_argument("--n-profile", type=int, help="points along the profile (default: wormsim.tooth.grid.N_PROFILE)")
    a = ap.parse_args()
    if a.n_profile is not None:  # a study of the profile's resolution (grid.flank_grid reads it when called)
        from wormsim.tooth import grid

        grid.N_PROFILE = a.n_profile
    from wormsim.tooth.grid import N_PROFILE

    out: dict = {"samples": a.samples, "approach_m": APPROACH_M, "n_profile": N_PROFILE, "cases": {}}
    for name in a.cases:
        out["cases"][name] = case(name, a.slices, a.samples)
        if a.record:
            record(a.record, out)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
