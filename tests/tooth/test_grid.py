"""Default slice count of the exact-flank contact (wormsim.tooth.kernel.default_slices; docs/contact3d.md,
"Default slice count"): at medium a slice's stiffness K / S is at most SLICE_SHARE of the zero-load mesh
stiffness's fluctuation k_p2p over a mesh cycle, rounded up to a multiple of SLICES_STEP, at least SLICES_MIN; fine
twice that; coarse 8; contact.slices overrides. The counts the convergence study measured: seat motor 32 (16 was not
converged); the fluctuation alone gives the screw jack 16 and involute_41 24, the floor 32 (decision 0054)."""

from __future__ import annotations

import numpy as np
import pytest

from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from wormsim.contact3d.mjcf import flank_slices
from wormsim.scenario import load_scenario
from wormsim.tooth import grid
from wormsim.tooth.mesh_stiffness import mesh_stiffness


@pytest.mark.parametrize(
    ("name", "slices", "by_fluctuation"), [("seat_motor", 32, 32), ("screw_jack", 32, 16), ("involute_41", 32, 24)]
)
def test_default_slices_follow_the_mesh_stiffness_fluctuation(name, slices, by_fluctuation):
    sc = load_scenario(SCENARIOS / f"{name}.yaml", ["simulation.resolution=medium"])
    assert flank_slices(sc) == slices
    fine = load_scenario(SCENARIOS / f"{name}.yaml", ["simulation.resolution=fine"])
    assert flank_slices(fine) == grid.SLICES_FINE_FACTOR * slices == 2 * slices
    ms = mesh_stiffness(derive(sc.gear), 1.0, "slices", grid.SLICES_TCA_SAMPLES)
    share = min(np.ptp(k) / np.mean(k) for k in (ms.k_mesh_fwd_n_per_m, ms.k_mesh_rev_n_per_m))
    # the smallest multiple of SLICES_STEP whose slice stiffness (k_mean / S) is within SLICE_SHARE of k_p2p ...
    assert 1 / by_fluctuation <= grid.SLICE_SHARE * share < 1 / (by_fluctuation - grid.SLICES_STEP)
    # ... and at least SLICES_MIN
    assert slices == max(grid.SLICES_MIN, by_fluctuation)


def test_coarse_and_the_explicit_count():
    seat = SCENARIOS / "seat_motor.yaml"
    assert flank_slices(load_scenario(seat, ["simulation.resolution=coarse"])) == grid.SLICES_COARSE
    assert flank_slices(load_scenario(seat, ["contact.slices=12"])) == 12


def test_a_mass_scaled_run_takes_at_most_16_slices():
    """flanks.SLICES_MASS_SCALED: mass scaling keeps the means only, so its default is not sized for the fluctuation
    (seat motor 20 s at S = 5000: the means at 16 and 32 slices within 0.02 %, 105 against 196 us per step); an
    explicit contact.slices is kept, and an unscaled run keeps the rule's 32."""
    from wormsim.contact3d.mjcf import build_model

    seat = SCENARIOS / "seat_motor.yaml"
    scaled = build_model(load_scenario(seat, ["simulation.mass_scaling=1000"]))
    assert scaled.plan.scaling.factor == 1000 and scaled.law.contacts_per_pair == grid.SLICES_MASS_SCALED == 16
    explicit = build_model(load_scenario(seat, ["simulation.mass_scaling=1000", "contact.slices=24"]))
    assert explicit.law.contacts_per_pair == 24
    assert build_model(load_scenario(seat)).law.contacts_per_pair == 32


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack", "involute_41"])
def test_the_resolution_levels_differ_in_what_check_prints(name):
    """simulation.resolution makes a difference (issue 31): `wormsim check`'s derived values give each level its own
    slice count, coarse < medium < fine, for the seeds (seat motor 8 / 32 / 64, screw jack 8 / 16 / 32, involute_41
    8 / 24 / 48)."""
    from wormsim.cli.check import level_lines

    counts = []
    for level in ("coarse", "medium", "fine"):
        sc = load_scenario(SCENARIOS / f"{name}.yaml", ["model=contact3d", f"simulation.resolution={level}"])
        line = next(x for x in level_lines(sc) if x.startswith("flank slices across the face:"))
        assert f"(default for resolution {level})" in line
        counts.append(int(line.split(":")[1].split()[0]))
    assert counts[0] == grid.SLICES_COARSE and counts[0] < counts[1] < counts[2] == 2 * counts[1], counts
