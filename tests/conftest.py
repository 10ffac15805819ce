"""Shared test fixtures and paths: ROOT (the repository), SCENARIOS (its scenarios/ folder); the `long` tests."""

from __future__ import annotations

import signal
from contextlib import contextmanager
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def scenario_dir() -> Path:
    """The seed scenarios (scenarios/)."""
    return SCENARIOS


# Tests kept out of `make test` for time (the suite must stay under 15 minutes on a 2-core machine); `make test-long`
# runs them. path under tests/ -> None (every test) or the values of the `name` parameter that are long.
LONG_TESTS: dict[str, set[str] | None] = {
    # slice and timestep convergence of the flank fluctuation: the seat motor's (step 6.4e-6 s, ~4 min) is long; the screw
    # jack's and involute_41's stay in `make test` (one CI-sized convergence test per seed)
    "contact3d/test_convergence.py": {"seat_motor"},
    # the convex-piece validation of the seeds (contact.geometry pieces); the default geometry's (flanks) is in
    # tests/contact3d/test_seeds.py and stays in `make test`
    "contact3d/test_seeds_pieces.py": {"seat_motor", "screw_jack", "involute_41"},
    "contact3d/test_errors_sidebands.py": None,
    "contact3d/test_random_forces.py": None,
    # left-q6-4start at 1400 rpm at 32 and 64 slices, one sample per step (minutes; a strict xfail)
    "contact3d/test_variety.py": {
        "test_left_q6_4start_at_1400_rpm_f_t_p2p_converged_in_slices"
    },  # four random gears' contact3d runs (issue 31), ~10 s each
    # a set may also name tests (their function names): WormPair against a contact3d run of the same gear (~20 s)
    "test_pair.py": {
        "test_pair_forces_and_efficiency_match_contact3d_on_the_same_gear",
        "test_pair_axial_force_against_din_3975",
    },
    "contact3d/test_flank_samples.py": {
        "test_held_run_ends_alike_on_the_compiled_and_the_python_path"
    },  # two held runs  # F_t sidebands of a wheel runout over a wheel revolution (~1 min)
    "contact3d/test_mass_scaling.py": {
        "unscaled"
    },  # the unscaled reference run of the scaled ones (240 000 steps, ~3 min)
    # contact3d and `wormsim mesh` per flank form (ZC's stay in `make test`; torsional's of every form too)
    "contact3d/test_flank_forms.py": {f"{k}_{f}" for k in ("contact3d", "mesh") for f in ("ZN1", "ZN2", "ZK")},
    "tooth/test_calculix.py": None,  # the CalculiX contact solve of a small case (minutes on one core)
    # the tooth compliance's FE on the seeds other than the screw jack (~15 s each cold; tests/tooth/test_ltca.py marks its own)
    "tooth/test_compliance.py": {"involute_41", "seat_motor", "test_random_gears_compliance_is_computed"},
    # contact3d on the shifted 1x40 (~2 min here with the kernel compiled) and the FVA REXS stage with its shafts
    # (~1 min); their torsional / wedge twins stay in `make test`
    "meshgen/test_profile_shift.py": {"contact3d_shifted_1x40"},
    "scenario/test_rexs.py": {"contact3d_fva", "contact3d_other"},
    # the FE mesher's every retry on a 120-tooth wheel (a strict xfail, minutes)
    "contact3d/test_mjcf.py": {"test_tooth_compliance_on_a_120_tooth_wheel"},
    # 100 random gears through every command (~1 min each); a handful stay in `make test`
    "cli/test_commands_random.py": {
        "test_random_gear_every_command_exits_0_2_or_3_long",
        "test_random_gears_mostly_run_long",
    },
}


def pytest_collection_modifyitems(config, items):
    for item in items:
        name = item.path.relative_to(ROOT / "tests").as_posix()
        if name not in LONG_TESTS:
            continue
        rule = LONG_TESTS[name]
        callspec = getattr(item, "callspec", None)
        if rule is None or (callspec is not None and callspec.params.get("name") in rule) or item.originalname in rule:
            item.add_marker(pytest.mark.long)


@contextmanager
def time_limit(seconds: int):
    """A hang becomes a failure (SIGALRM), not a stuck CI job."""

    def expire(signum, frame):
        raise TimeoutError(f"no result within {seconds} s")

    old = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
