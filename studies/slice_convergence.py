"""F_t p2p and TE p2p of the exact-flank contact against the slice count (issue 13; docs/contact3d.md, "Default slice
count"): the seeds' CI runs (tests/contact3d/test_seeds_pieces.py with contact.geometry flanks) and the variety variants
(tests/contact3d/test_variety.py), each at the given `contact.slices`, with F_t's p2p below 1 kHz (its meshing band,
under the contact modes) and the summary's per-step wall time (compare within one run of this script only: the
machine is shared). One line per run, flushed, so a long sweep can be cut.

    .venv/bin/python studies/slice_convergence.py [--cases seat_motor screw_jack left-ZA ...] [--slices 12 16 24 32]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.conftest import SCENARIOS  # noqa: E402
from tests.contact3d.test_seeds_pieces import CI  # noqa: E402
from tests.contact3d.test_variety import FAST, FLANK_GEARS, GEAR  # noqa: E402
from wormsim.contact3d.mjcf import flank_slices  # noqa: E402
from wormsim.contact3d.runner import simulate  # noqa: E402
from wormsim.results.metrics import p2p_below  # noqa: E402
from wormsim.scenario import load_scenario  # noqa: E402

BAND_HZ = 1000.0  # F_t's meshing band: below the lowest contact mode measured (involute_41, 1.3-1.8 kHz)


def scenario(name: str, slices: int | None):
    extra = [] if slices is None else [f"contact.slices={slices}"]
    if name in CI:
        return load_scenario(SCENARIOS / f"{name}.yaml", [*CI[name], "contact.geometry=flanks", *extra])
    return load_scenario(GEAR, [*FAST, *FLANK_GEARS[name], *extra])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="+", default=["screw_jack", "seat_motor"])
    ap.add_argument("--slices", type=int, nargs="+", default=[12, 16, 24, 32, 48, 64])
    ap.add_argument("--default", action="store_true", help="also run each case at its default slice count")
    ap.add_argument("--save", type=Path, help="folder: each run's t_s, tangential_force_n, transmission_error_rad")
    a = ap.parse_args()
    for name in a.cases:
        runs = ([None] if a.default else []) + a.slices
        for s in runs:
            sc = scenario(name, s)
            res = simulate(sc)
            r = res.summary
            t = res.series["t_s"]
            m = (t >= r["steady_window_s"][0]) & (t <= r["steady_window_s"][1])
            lo = p2p_below(t[m], res.series["tangential_force_n"][m], BAND_HZ)
            if a.save:
                a.save.mkdir(parents=True, exist_ok=True)
                np.savez(
                    a.save / f"{name}_S{flank_slices(sc)}.npz",
                    t_s=res.series["t_s"],
                    f_t=res.series["tangential_force_n"],
                    te=res.series["transmission_error_rad"],
                    window=np.array(r["steady_window_s"]),
                    f_mesh=r["mesh_frequency_theory_hz"] if "mesh_frequency_theory_hz" in r else np.nan,
                )
            print(
                f"{name:20s} S={flank_slices(sc):3d}{'*' if s is None else ' '} "
                f"F_t p2p {r['tangential_force_p2p_n']:9.4f} N  TE p2p {r['transmission_error_p2p_urad']:9.3f} urad  "
                f"F_t < {BAND_HZ:.0f} Hz p2p {lo:9.4f} N  F_t mean {r['tangential_force_mean_n']:9.2f} N  "
                f"contacts {r['contacts_mean']:6.1f}  "
                f"step {r['step_wall_us']:7.1f} us",
                flush=True,
            )


if __name__ == "__main__":
    main()
