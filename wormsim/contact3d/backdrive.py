"""The back-drive probe (simulation.backdrive_probe: true): after the forward run, a second contact3d run of the same
gear with the wheel driving, to measure what summary.json's `self_locking` and `efficiency_backdrive` state from
rho' and gamma (docs/outputs.md).

The probe: the wheel speed-driven at the forward run's mean wheel speed (same ramps), the worm loaded with
T1 = T2 efficiency_backdrive / ratio, the torque that carries the forward run's wheel torque T2 through the mesh when
back-driven at the stated efficiency (0 when the pair is stated self-locking: a free worm). A pair that locks stops
the speed-driven wheel: the run's lock guard (LockedError), or a worm turning below HELD_BELOW of the wheel command
times the ratio over the probe's steady window (a creeping worm), is the measured self-locking. Otherwise the
probe's efficiency (worm power out / wheel power in over its steady window) is the measured back-driving efficiency.
The probe costs a second run of simulation.duration_s.
"""

from __future__ import annotations

from wormsim.exceptions import LockedError
from wormsim.results.result import Result
from wormsim.scenario import Scenario

HELD_BELOW = 0.5  # worm speed / (wheel command x ratio) below this: the pair holds (as the lock guard's criterion)


def probe_scenario(scenario: Scenario, forward: dict) -> Scenario:
    """The back-driven copy of a forward scenario (module docstring)."""
    d = scenario.model_dump()
    t2 = abs(scenario.load.torque_nm)
    d["drive"] = {"on": "wheel", "speed_rpm": forward["wheel_speed_mean_rpm"], "ramp_s": scenario.drive.ramp_s}
    d["load"] = {
        "on": "worm",
        "torque_nm": t2 * forward["efficiency_backdrive"] / forward["ratio_theory"],
        "start_s": scenario.load.start_s,
        "ramp_s": scenario.load.ramp_s,
    }
    d["simulation"]["backdrive_probe"] = False
    return Scenario.model_validate(d)


def probe(scenario: Scenario, forward: dict, simulate) -> dict:
    """The summary keys `backdrive_measured_*` of the probe run (`simulate`: contact3d's simulate)."""
    sc = probe_scenario(scenario, forward)
    keys = {
        "backdrive_probe_wheel_speed_rpm": sc.drive.speed_rpm,
        "backdrive_probe_worm_torque_nm": sc.load.torque_nm,
    }
    try:
        res: Result = simulate(sc)
    except LockedError as exc:
        return {
            **keys,
            "backdrive_measured_self_locking": True,
            "backdrive_measured_efficiency": 0.0,
            "backdrive_measured_message": str(exc),
        }
    s = res.summary
    share = s["worm_speed_mean_rpm"] / (sc.drive.speed_rpm * forward["ratio_theory"])
    locked = share < HELD_BELOW
    return {
        **keys,
        "backdrive_measured_self_locking": bool(locked),
        "backdrive_measured_efficiency": 0.0 if locked else s["efficiency"],
        "backdrive_measured_message": f"worm back-driven at {s['worm_speed_mean_rpm']:.4g} rpm, {100 * share:.3g} % "
        f"of the wheel command times the ratio" + (" (held: self-locking)" if locked else ""),
    }
