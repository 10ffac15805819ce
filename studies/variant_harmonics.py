"""Quasi-static F_t harmonics of the exact-flank kernel on the variety variants against slice count (issue 13;
docs/contact3d.md, "Variety with exact flanks"). No MuJoCo step: the worm is set over one mesh cycle, the wheel at
the conjugate angle minus a fixed lag, and F_t = sum(w k_c depth (r x n)_z) / r2 from FlankContacts.find. The lag is
solved so that the cycle's mean F_t carries the run's load (load.torque_nm / r2). Printed per slice count: the
harmonics 1..N of F_t / mean, next to the TCA's k(theta) harmonics / mean (wormsim.tooth.mesh_stiffness, zero
load, independent of the slices).

    .venv/bin/python studies/variant_harmonics.py [--slices 8 16 32] [--gears wide-z80-q16 ...] [--harmonics 12]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.contact3d.test_variety import FAST, FLANK_GEARS, GEAR  # noqa: E402
from wormsim.contact3d.flank_step import FlankContacts  # noqa: E402
from wormsim.contact3d.mjcf import build_model  # noqa: E402
from wormsim.scenario import load_scenario  # noqa: E402
from wormsim.tooth.mesh_stiffness import compute  # noqa: E402


def f_t(bm, fc, d, th1: float, lag: float) -> float:
    g = bm.geometry
    d.qpos[fc.qa1] = th1
    d.qpos[fc.qa2] = g.hand * g.z1 / g.z2 * th1 - g.hand * lag
    n = fc.find(d)
    f = fc.weight[:n] * bm.law.contact_stiffness_n_per_m * fc.depth[:n]
    return float((np.cross(fc.pos[:n], fc.nrm[:n])[:, 2] * f).sum() / g.r2)


def sweep(bm, fc, d, lag: float, n: int) -> np.ndarray:
    per = 2 * math.pi / bm.geometry.z1
    return np.array([f_t(bm, fc, d, per * i / n, lag) for i in range(n)])


def harmonics(x: np.ndarray, n: int) -> np.ndarray:
    return np.abs(np.fft.rfft(x))[1 : n + 1] / len(x) * 2 / x.mean()


def kernel_harmonics(name: str, slices: int, n_harm: int, samples: int) -> tuple[np.ndarray, float, float]:
    sc = load_scenario(GEAR, FAST + FLANK_GEARS[name] + [f"contact.slices={slices}"])
    bm = build_model(sc)
    g = bm.geometry
    fc, d = FlankContacts(bm, slices), mujoco.MjData(bm.model)
    target = sc.load.torque_nm / g.r2
    bl = g.backlash / (2 * g.r2)
    # F_t is nearly linear in the lag past the backlash: secant, then Newton on the mean
    m1, m2 = sweep(bm, fc, d, 2 * bl, 200).mean(), sweep(bm, fc, d, 3 * bl, 200).mean()
    lag = 2 * bl + (target - m1) / (m2 - m1) * bl
    for _ in range(3):
        m, mb = sweep(bm, fc, d, lag, 200).mean(), sweep(bm, fc, d, lag * 1.001, 200).mean()
        lag += (target - m) / ((mb - m) / (lag * 0.001))
    F = sweep(bm, fc, d, lag, samples)
    return harmonics(F, n_harm), float(F.mean()), float(np.ptp(F))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--slices", type=int, nargs="+", default=[8, 16, 32])
    ap.add_argument("--gears", nargs="+", default=list(FLANK_GEARS))
    ap.add_argument("--harmonics", type=int, default=12)
    ap.add_argument("--samples", type=int, default=800)
    a = ap.parse_args()
    for name in a.gears:
        g = build_model(load_scenario(GEAR, FAST + FLANK_GEARS[name])).geometry
        k = compute(g, 1.0, "x", 400).k_mesh_fwd_n_per_m
        hk = harmonics(k, a.harmonics)
        print(f"{name}: TCA k p2p/mean {np.ptp(k) / k.mean():.3f}; harmonics 1-{a.harmonics} / mean")
        print("   TCA      " + " ".join(f"{v:.4f}" for v in hk), f"(largest: {int(np.argmax(hk)) + 1})")
        for s in a.slices:
            h, mean, p2p = kernel_harmonics(name, s, a.harmonics, a.samples)
            print(
                f"   S={s:<3d}    " + " ".join(f"{v:.4f}" for v in h),
                f"(largest: {int(np.argmax(h)) + 1}; mean {mean:.1f} N, p2p/mean {p2p / mean:.3f})",
                flush=True,
            )


if __name__ == "__main__":
    main()
