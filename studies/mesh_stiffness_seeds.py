"""The torsional level's mesh stiffness k(theta) on each seed file as it is (docs/torsional.md, "Mesh stiffness"):
the tooth contact analysis' mean, min and max along the line of action, the teeth and contact-line length in
contact, the tooth-pair stiffness K it is compared with (wormsim.tooth.stiffness.pair_stiffness_n_per_m: the
scenario's, the teeth's or the Hertz line contact's over b2), and the full-band force peak of the run.
Writes the record docs/data/mesh_stiffness_seeds.json.

    .venv/bin/python studies/mesh_stiffness_seeds.py
"""

from __future__ import annotations

from pathlib import Path

from meshgen.geometry import derive
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.tooth.stiffness import pair_stiffness_n_per_m
from wormsim.torsional.dynamics import simulate

ROOT = Path(__file__).resolve().parents[1]
SEEDS = ("seat_motor", "screw_jack", "involute_41")
KEYS = (
    "mesh_stiffness_samples",
    "mesh_stiffness_source",
    "mesh_stiffness_mean_n_per_m",
    "mesh_stiffness_min_n_per_m",
    "mesh_stiffness_max_n_per_m",
    "contact_line_length_mean_mm",
    "teeth_in_contact_mean",
    "force_peak_full_band_hz",
    "mesh_frequency_theory_hz",
)


def main() -> None:
    runs = {}
    for seed in SEEDS:
        sc = load_scenario(ROOT / "scenarios" / f"{seed}.yaml", ["model=torsional"])
        g = derive(sc.gear)
        pair, _ = pair_stiffness_n_per_m(sc.contact, g, sc.materials)
        s = simulate(sc).summary
        runs[seed] = {
            "pair_stiffness_n_per_m": pair,
            "face_width_mm": g.face_width * 1e3,
            **{k: s.get(k) for k in KEYS},
        }
        print(seed, runs[seed], flush=True)
    print(record("mesh_stiffness_seeds", {"runs": runs}))


if __name__ == "__main__":
    main()
