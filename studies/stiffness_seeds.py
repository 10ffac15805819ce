"""The seeds with each source of the tooth-pair stiffness (docs/contact3d.md, "Tooth stiffness on the seeds"): the
CI-sized runs of tests/contact3d/test_seeds_pieces.py (`contact.geometry: flanks`) at contact3d and at torsional, each

  seed:   the scenario file as it is where it pins its seed's ADAMS constant (seat_motor, screw_jack:
          contact.stiffness_n_per_m; involute_41 gives none, its file's run is the default, teeth),
  hertz:  contact.stiffness_n_per_m=null, contact.stiffness_model=hertz (pi E* / 4 per length: rigid teeth),
  teeth:  contact.stiffness_n_per_m=null, contact.stiffness_model=teeth (the teeth's compliance,
          wormsim.tooth.compliance), where the code has it,

in one process, so that the speeds (wall seconds per simulated second, contact3d) compare on the same machine load.
The first contact3d run of a process includes the flank kernel's compile and is repeated. Writes the record
docs/data/stiffness_seeds.json.

    .venv/bin/python studies/stiffness_seeds.py [--modes seed,hertz,teeth] [--seeds seat_motor,screw_jack,involute_41]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from wormsim.contact3d.runner import simulate as simulate_c3d
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.torsional.dynamics import simulate as simulate_tor

ROOT = Path(__file__).resolve().parents[1]
MODES = {
    "seed": [],
    "hertz": ["contact.stiffness_n_per_m=null", "contact.stiffness_model=hertz"],
    "teeth": ["contact.stiffness_n_per_m=null", "contact.stiffness_model=teeth"],
}
C3D_KEYS = (
    "ratio",
    "ratio_theory",
    "tangential_force_mean_n",
    "radial_force_mean_n",
    "axial_force_mean_n",
    "efficiency",
    "efficiency_theory",
    "tangential_force_p2p_n",
    "transmission_error_p2p_urad",
    "teeth_in_contact_mean",
    "contact_pattern_centroid_face_mm",
    "contact_pattern_centroid_radius_mm",
    "contact_pattern_extent_face_mm",
    "contact_pressure_max_mpa",
    "contact_pressure_mean_mpa",
    "max_penetration_um",
    "mesh_frequency_hz",
    "contact_pair_stiffness_n_per_m",
    "contact_stiffness_source",
    "mesh_stiffness_mean_n_per_m",
    "mesh_stiffness_per_width_n_per_mm_um",
    "transmission_error_loaded_p2p_urad",
    "load_share_max",
    "timestep_s",
    "timestep_stable_limit_s",
    "step_wall_us",
    "steps",
)
TOR_KEYS = (
    "ratio",
    "tangential_force_mean_n",
    "efficiency",
    "tangential_force_p2p_n",
    "transmission_error_p2p_urad",
    "mesh_stiffness_source",
    "mesh_stiffness_mean_n_per_m",
    "mesh_stiffness_per_width_n_per_mm_um",
    "mesh_natural_frequency_hz",
    "transmission_error_loaded_p2p_urad",
    "load_share_max",
    "teeth_in_contact_mean",
)


def _c3d(name: str, sets: list[str]) -> dict:
    sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml", sets)
    t0 = time.perf_counter()
    res = simulate_c3d(sc)
    wall = time.perf_counter() - t0
    s = res.summary
    out = {k: s.get(k) for k in C3D_KEYS}
    out["sim_time_s"] = res.sim_time_s
    out["wall_s"] = wall  # build, stepping and summary
    out["wall_s_per_simulated_s"] = s["step_wall_us"] * 1e-6 * res.steps / res.sim_time_s  # the stepping loop
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--modes", default="seed,hertz,teeth")
    ap.add_argument("--seeds", default="seat_motor,screw_jack,involute_41")
    args = ap.parse_args()
    modes = [m for m in args.modes.split(",") if m]
    seeds = [n for n in args.seeds.split(",") if n]
    sys.path.insert(0, str(ROOT))
    from tests.contact3d.test_seeds_pieces import CI

    runs: dict[str, dict] = {}
    warm = False
    for name in seeds:
        sets = CI[name]
        runs[name] = {}
        pinned = load_scenario(ROOT / "scenarios" / f"{name}.yaml").contact.stiffness_n_per_m is not None
        for mode in modes:
            if mode == "seed" and not pinned:  # the file gives no K: its run is the default's (teeth)
                continue
            over = [*sets, "contact.geometry=flanks", *MODES[mode]]
            if not warm:  # the kernel's compile out of the timing
                _c3d(name, over)
                warm = True
            c3d = _c3d(name, over)
            tor = simulate_tor(load_scenario(ROOT / "scenarios" / f"{name}.yaml", [*over, "model=torsional"])).summary
            runs[name][mode] = {"overrides": over, "contact3d": c3d, "torsional": {k: tor.get(k) for k in TOR_KEYS}}
            print(name, mode, c3d["wall_s_per_simulated_s"], c3d["timestep_s"], flush=True)
    record("stiffness_seeds", {"modes": modes, "seeds": seeds, "runs": runs})


if __name__ == "__main__":
    main()
