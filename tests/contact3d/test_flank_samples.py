"""The runner's record intervals compiled together (wormsim.contact3d.flank_samples) give what the per-sample Python
path gives, bit for bit (series, summary, contact points, contact pattern), and its guards' errors word for word."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import wormsim.contact3d.flank_samples as FS
from tests.contact3d.test_guards import WHEEL_DRIVEN
from wormsim.contact3d.runner import simulate, warm_runs
from wormsim.exceptions import SimulationError
from wormsim.runtime import jit_cache
from wormsim.scenario import load_scenario

SCEN = Path(__file__).resolve().parents[2] / "scenarios"
JACK = SCEN / "screw_jack.yaml"
DEMO = SCEN / "seat_motor_demo.yaml"
SHORT = ["simulation.duration_s=0.03", "simulation.resolution=coarse"]
GROUP = ["contact.friction_static=null", "contact.friction_dynamic=null", "contact.friction_group=III"]
CASES = {
    "every step, STEP friction": (JACK, SHORT + ["simulation.record_every=1"]),
    "every 3rd step": (SCEN / "involute_41.yaml", SHORT + ["simulation.record_every=3"]),
    "friction group": (JACK, SHORT + GROUP + ["simulation.record_every=2"]),
    "one contact per tooth flank": (JACK, SHORT + ["contact.flank_contacts=tooth", "simulation.record_every=1"]),
    "frictionless": (
        JACK,
        SHORT + ["contact.friction_static=null", "contact.friction_dynamic=null", "contact.friction=0"],
    ),
    # the friction law's stick state (wheel-driven, mu_s 0.3 deg above and mu_d 0.3 deg below the locking boundary): a
    # worm torque assisting the back-drive at 2 x the break-away torque, T2 / i tan(0.3 deg) / tan(gamma); the stuck
    # samples go to the Python path (wormsim.contact3d.breakaway), the sliding ones stay compiled
    "stick state, breaking away": (
        DEMO,
        [
            "simulation.resolution=coarse",
            "simulation.duration_s=0.012",
            "drive.on=wheel",
            "drive.speed_rpm=null",
            "drive.torque_nm=2.0",
            "drive.ramp_s=0.002",
            "load.on=worm",
            "load.torque_nm=-0.0047",
            "load.start_s=0.003",
            "load.ramp_s=0.001",
            "contact.friction=null",
            "contact.friction_static=0.0877",
            "contact.friction_dynamic=0.0773",
            "simulation.record_every=1",
        ],
    ),
    # displaced poses (wormsim.tooth.pose): assembly errors, and shafts on bearings (a compliant worm shaft that
    # bends: springs; a rigid wheel shaft: mj_rnePostConstraint's reactions)
    "errors": (JACK, SHORT + ["errors.center_distance_mm=0.02", "errors.shaft_angle_deg=0.05"]),
    "shafts": (
        JACK,
        SHORT
        + [
            "shafts={worm: {bearings_mm: [-60, 60], radial_stiffness_n_per_um: 500, bending: true},"
            " wheel: {bearings_mm: [-30, 30]}}",
            "simulation.record_every=2",
        ],
    ),
}
WALL = ("step_wall_us", "wall_time_s")


def _run(path, sets, enabled: bool, monkeypatch, counts: dict | None = None):
    monkeypatch.setattr(FS, "ENABLED", enabled)
    if counts is not None:
        # a cold kernel cache runs its warm-up runs inside the first simulate (wormsim.runtime.jit_cache.ensure_warm):
        # done first, so that the counts are this run's samples alone
        jit_cache.ensure_warm(warm_runs)
        run = FS.FlankSamples.run

        def counted(self, *a):
            out = run(self, *a)
            counts["compiled"] += out[0] - a[2]
            counts["python"] += out[1] != FS.EV_NONE  # the event: the sample left to the Python path
            return out

        monkeypatch.setattr(FS.FlankSamples, "run", counted)
    return simulate(load_scenario(path, sets))


def _equal(a, b) -> bool:
    """a == b, NaN equal to NaN."""
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b):
        return True
    return a == b


def _same(a, b) -> bool:
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


@pytest.mark.parametrize("case", list(CASES))
def test_compiled_samples_equal_the_python_path(case, monkeypatch):
    path, sets = CASES[case]
    counts = {"compiled": 0, "python": 0}
    fast = _run(path, sets, True, monkeypatch, counts)
    slow = _run(path, sets, False, monkeypatch)
    n = len(fast.series["t_s"])
    # the compiled call did the samples, the Python path only the start-up's changing friction and guard checks
    assert counts["compiled"] > 0.5 * n, (counts, n)
    assert counts["compiled"] + counts["python"] == n
    assert [k for k in fast.series if not _same(fast.series[k], slow.series[k])] == []
    assert fast.summary.keys() == slow.summary.keys()
    differ = [k for k in fast.summary if k not in WALL and not _equal(fast.summary[k], slow.summary[k])]
    assert differ == [], [(k, fast.summary[k], slow.summary[k]) for k in differ]
    for k in ("points_tooth0", "points_world", "forces_world"):
        assert _same(fast.extra[k], slow.extra[k]), k
    pa, pb = fast.extra["flank_pattern"], slow.extra["flank_pattern"]
    assert pa.keys() == pb.keys() and all(_same(pa[k], pb[k]) for k in pa)


def test_friction_checks_that_pass_stay_compiled(monkeypatch):
    """The friction guard's checks after the ramps (every CHECK_EVERY_S, 0.5 ms: 50 of them over 25 ms) pass inside
    the compiled samples (flank_samples.friction_aligned) instead of each handing its sample to the Python path; the
    run is the Python path's bit for bit, and the guard's next check is where FrictionGuard.check leaves it."""
    from wormsim.contact3d.friction_guard import CHECK_EVERY_S

    sets = SHORT + ["drive.ramp_s=0.005", "load.ramp_s=0.005", "simulation.record_every=1"]
    counts = {"compiled": 0, "python": 0}
    fast = _run(JACK, sets, True, monkeypatch, counts)
    slow = _run(JACK, sets, False, monkeypatch)
    checks = (0.03 - 0.005) / CHECK_EVERY_S
    assert counts["python"] < 0.2 * checks, counts
    assert [k for k in fast.series if not _same(fast.series[k], slow.series[k])] == []
    differ = [k for k in fast.summary if k not in WALL and not _equal(fast.summary[k], slow.summary[k])]
    assert differ == [], [(k, fast.summary[k], slow.summary[k]) for k in differ]


HELD = (
    JACK,
    [
        *WHEEL_DRIVEN,
        "contact.friction=0.2",
        "simulation.duration_s=0.085",
    ],
)  # a wheel back-driving a self-locking pair: the run ends held (wormsim.physics.locking)

GUARDS = {
    "penetration": (
        DEMO,
        ["drive.speed_rpm=0", "drive.ramp_s=0", "load.ramp_s=0", "load.torque_nm=700", "simulation.duration_s=0.001"],
    ),
    "teeth jumped": (
        DEMO,
        ["drive.speed_rpm=0", "drive.ramp_s=0", "load.ramp_s=0", "load.torque_nm=2000", "simulation.duration_s=0.001"],
    ),
    "diverged": (DEMO, ["simulation.timestep_s=1e-4", "simulation.duration_s=0.005"]),
    "bad qacc": (DEMO, ["simulation.duration_s=0.004", "load.torque_nm=100", "load.ramp_s=0", "drive.ramp_s=0"]),
}


def test_held_run_ends_alike_on_the_compiled_and_the_python_path(monkeypatch):
    """The held back-drive (tests/contact3d/test_guards.py, before: the friction guard's locked error): the run ends
    at the same sample with the same locked keys either way."""
    fast = _run(*HELD, True, monkeypatch)
    slow = _run(*HELD, False, monkeypatch)
    assert fast.summary["locked"] is True and slow.summary["locked"] is True
    assert fast.sim_time_s == slow.sim_time_s and len(fast.series["t_s"]) == len(slow.series["t_s"])
    for k in ("holding_torque_nm", "creep_speed_rpm"):
        assert fast.summary[k] == slow.summary[k], k


@pytest.mark.parametrize("case", list(GUARDS))
def test_guards_stop_the_compiled_samples_with_the_python_paths_error(case, monkeypatch):
    """tests/contact3d/test_guards.py's failing runs: the same exception type and message either way."""
    path, sets = GUARDS[case]
    errs = []
    for enabled in (True, False):
        with pytest.raises(SimulationError) as exc:
            _run(path, sets, enabled, monkeypatch)
        errs.append((type(exc.value), str(exc.value)))
    assert errs[0] == errs[1]


def test_one_compiled_signature_with_and_without_one_contact_per_tooth_flank():
    """run_samples and contact_rows get the merge's arrays either way (the kernel's merge flag chooses): one compiled
    specialisation for per-slice and per-tooth-flank runs, not one per tuple and None (issue 33: fewer
    specialisations; the warm-up then covers both)."""
    for extra in ([], ["contact.flank_contacts=tooth"]):
        sc = load_scenario(JACK, ["simulation.duration_s=0.002", "simulation.resolution=coarse", *extra])
        simulate(sc)
    assert len(FS.run_samples.signatures) == 1, FS.run_samples.signatures
    # (a callee is typed only where its caller compiles here: none where run_samples came from the cache)
    assert len(FS.contact_rows.signatures) <= 1, FS.contact_rows.signatures
