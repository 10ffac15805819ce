"""Is the default slice count converged? (issue 31, item 2; docs/contact3d.md, "Default slice count"): each case at
its default `contact.slices` (wormsim.tooth.grid.default_slices) and at twice that, F_t p2p over the steady window
(whole and below 1 kHz, the meshing band), p_H max (wormsim.tooth.hertz (4), the line load averaged over one axial
module of contact line) and, for comparison, the largest p_H of one contact (hertz (3)), and their change from S to
2 S. Each case at the default contact stiffness, the teeth's compliance (the variety gears' test asset pins Hertz's:
the sweep sets contact.stiffness_model=teeth); Hertz's where the teeth's compliance fails on the gear (gmsh; the
record says so, `hertz_fallback`). The cases: the variety gears (tests/contact3d/test_variety.py FLANK_GEARS), three
random gears (tests/contact3d/test_random_forces.py; --cases random4 .. further draws of its generator, and steep,
its STEEP gear) and the seeds' CI runs with flanks
(tests/contact3d/test_seeds_pieces.py CI; the seat motor and the screw jack set their own
contact.stiffness_n_per_m). Writes docs/data/RECORD.json after each case (a long sweep can be cut).

    .venv/bin/python studies/slice_convergence_default.py [--cases left-ZA random0 screw_jack ...] [--medium]
        [--record NAME] [--save DIR]

--medium runs the variety and random gears at simulation.resolution medium (the default resolution; their test
configurations are coarse, 8 slices). --save writes each run's contact pattern table and F_t (npz). --factor F
compares F x the default count against 2 F x it (the record's default_slices is then F x the default). --impedance D
runs with the contacts' impedance d = D (wormsim.contact3d.law.IMPEDANCE, the constraint's added mass d / (1 - d)
of the mesh's effective mass per contact row) instead of the model's; the record says which (`impedance`).
--n-profile N: the flank grid's points along the profile instead of wormsim.tooth.grid.N_PROFILE (`n_profile`).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.conftest import SCENARIOS  # noqa: E402
from tests.contact3d.test_random_forces import GEARS, STEEP, _draw, _scenario  # noqa: E402
from tests.contact3d.test_seeds_pieces import CI  # noqa: E402
from tests.contact3d.test_variety import FAST, FLANK_GEARS, GEAR  # noqa: E402
from wormsim.contact3d.mjcf import flank_slices  # noqa: E402
from wormsim.contact3d.runner import simulate  # noqa: E402
from wormsim.exceptions import SimulationError  # noqa: E402
from wormsim.results.metrics import p2p_below  # noqa: E402
from wormsim.results.provenance import record  # noqa: E402
from wormsim.scenario import Scenario, load_scenario  # noqa: E402

BAND_HZ = 1000.0  # F_t's meshing band (studies/slice_convergence.py)
CASES = [*FLANK_GEARS, *(f"random{i}" for i in range(len(GEARS))), "screw_jack", "involute_41", "seat_motor"]


def scenario(name: str, slices: int | None, medium: bool = False, hertz: bool = False) -> Scenario:
    """The case at `slices` (None: its default), at the teeth's stiffness (hertz: Hertz's)."""
    extra = [] if slices is None else [f"contact.slices={slices}"]
    stiffness = f"contact.stiffness_model={'hertz' if hertz else 'teeth'}"
    if name in CI:  # the seeds' own stiffness (the screw jack and the seat motor set contact.stiffness_n_per_m)
        return load_scenario(
            SCENARIOS / f"{name}.yaml", [*CI[name], "contact.geometry=flanks", *extra, *([stiffness] if hertz else [])]
        )
    if name.startswith("random") or name == "steep":
        # random{i}: tests/contact3d/test_random_forces.py's i-th draw (beyond its GEARS: further draws of the same
        # generator, cases no setting was tuned on; the 4th, random3, is refused as undercut); steep: its STEEP
        gear = (
            STEEP
            if name == "steep"
            else GEARS[int(name[6:])]
            if int(name[6:]) < len(GEARS)
            else _draw(int(name[6:]) + 1)[-1]
        )
        d = _scenario(gear).model_dump()
        if medium:
            d["simulation"]["resolution"] = "medium"
        if slices is not None:
            d["contact"]["slices"] = slices
        d["contact"]["stiffness_model"] = "hertz" if hertz else "teeth"
        return Scenario.model_validate(d)
    res = ["simulation.resolution=medium"] if medium else []
    return load_scenario(GEAR, [*FAST, *FLANK_GEARS[name], *res, *extra, stiffness])


def _table(res) -> np.ndarray:
    """The run's contact pattern rows (wormsim.tooth.hertz.PatternLog.table)."""
    log = res.extra.get("flank_pattern_log")
    return log.table() if log is not None else np.zeros((0, 8))


def cell_peak_mpa(T, t: np.ndarray, window) -> float | None:
    """The largest p_H of one contact, (3) of wormsim.tooth.hertz, over the contacts in the steady window carrying at
    least 1 % of their mean normal force (the one-contact maximum, for comparison with the averaged (4))."""
    if T is None or not len(T):
        return None
    inwin = (t >= window[0]) & (t <= window[1])
    T = T[inwin[T[:, 0].astype(int)] & (T[:, 4] > 0)]
    p = np.where(T[:, 4] >= 0.01 * T[:, 4].mean(), T[:, 5], np.nan)
    return float(np.nanmax(p) * 1e-6) if np.isfinite(p).any() else None


def measure(sc: Scenario, save: Path | None = None, tag: str = "") -> dict:
    t0 = time.perf_counter()
    res = simulate(sc)
    r, S = res.summary, res.series
    t = S["t_s"]
    m = (t >= r["steady_window_s"][0]) & (t <= r["steady_window_s"][1])
    if save is not None:
        save.mkdir(parents=True, exist_ok=True)
        pat = res.extra["flank_pattern"]
        np.savez(
            save / f"{tag}_S{r['flank_slices']}.npz",
            table=_table(res),
            t_s=t,
            window=np.array(r["steady_window_s"]),
            f_t=S["tangential_force_n"],
            rho_m=pat["rho_m"],
            zeta_m=pat["zeta_m"],
        )
    return {
        "slices": r["flank_slices"],
        "flank_contacts": r["flank_contacts"],
        "ft_p2p_n": r["tangential_force_p2p_n"],
        "ft_p2p_band_n": float(p2p_below(t[m], S["tangential_force_n"][m], BAND_HZ)),
        "ph_max_mpa": r.get("contact_pressure_max_mpa"),
        "ph_max_cell_mpa": cell_peak_mpa(_table(res), t, r["steady_window_s"]),
        "ft_mean_n": r["tangential_force_mean_n"],
        "timestep_s": r["timestep_s"],
        "contact_pair_stiffness_n_per_m": r.get("contact_pair_stiffness_n_per_m"),
        "contact_stiffness_source": r.get("contact_stiffness_source"),
        "wall_s": time.perf_counter() - t0,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="+", default=CASES)
    ap.add_argument("--medium", action="store_true")
    ap.add_argument("--record", default="slice_convergence_default")
    ap.add_argument("--save", type=Path, help="folder: each run's contact pattern table and F_t (npz)")
    ap.add_argument("--factor", type=int, default=1, help="compare factor x the default against twice that")
    ap.add_argument("--impedance", type=float, help="the contacts' impedance d instead of law.IMPEDANCE")
    ap.add_argument("--n-profile", type=int, help="points along the profile (default: wormsim.tooth.grid.N_PROFILE)")
    a = ap.parse_args()
    if a.n_profile is not None:  # a study of the profile's resolution (grid.flank_grid reads it when called)
        from wormsim.tooth import grid

        grid.N_PROFILE = a.n_profile
    if a.impedance is not None:  # an experiment on the law's constant (contact_law reads it at each build)
        from wormsim.contact3d import law

        law.IMPEDANCE = a.impedance
    from wormsim.contact3d.law import IMPEDANCE
    from wormsim.tooth.grid import N_PROFILE

    out: dict = {"band_hz": BAND_HZ, "medium": a.medium, "factor": a.factor, "impedance": IMPEDANCE}
    out |= {"n_profile": N_PROFILE, "cases": {}}
    for name in a.cases:
        s0 = a.factor * flank_slices(scenario(name, None, a.medium))
        try:
            hertz = False
            runs = [measure(scenario(name, s, a.medium), a.save, name) for s in (s0, 2 * s0)]
        except SimulationError as e:  # the teeth's compliance fails on this gear (gmsh): Hertz's stiffness instead
            print(name, "teeth's compliance failed, Hertz's stiffness:", str(e)[:120], flush=True)
            hertz = True
            runs = [measure(scenario(name, s, a.medium, True), a.save, name) for s in (s0, 2 * s0)]
        ch = {
            k: (runs[0][k] / runs[1][k] - 1) if runs[1][k] else None
            for k in ("ft_p2p_n", "ft_p2p_band_n", "ph_max_mpa", "ph_max_cell_mpa")
        }
        out["cases"][name] = {
            "default_slices": s0,
            "hertz_fallback": hertz,
            "runs": runs,
            "change_default_vs_double": ch,
        }
        print(name, s0, {k: None if v is None else round(100 * v, 1) for k, v in ch.items()}, flush=True)
        record(a.record, out)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
