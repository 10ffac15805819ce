"""The stick state's break-away (docs/decisions/0058-breakaway-on-static-friction.md): static holding from rest and
the break-away under a worm torque that assists the back-drive, at contact3d, with the CPU cost of the break-away's
check. Writes docs/data/breakaway.json.

- The user's gear of tests/results/test_trust.py (HOLD_FROM_REST: 150 N m on the wheel, the worm free, mu_s / mu_d 0.3
  deg above / below the locking boundary, 0.03 s): the worm's creep after 2 ms and 20 ms ramps, with the stick state
  and with constant mu_s, and the frictionless run's speed at the end (the free speed).
- The same held pair with a worm torque assisting the back-drive from 5 ms over 2 ms, at shares of the hand formula's
  break-away torque T2 / i tan(rho'_s - gamma) / tan(gamma).
- The held pair's need / limit on the worm's hinge (wormsim.contact3d.breakaway) over the 2 ms run.
- The seat motor demo gear (coarse, 2 N m on the wheel, 0.01 s): the worm's speed at the end after 2, 1 and 0.5 ms
  ramps, and frictionless.
- CPU per step of the held run (0.1 s, 20 ms ramp, every step a sample) with the stick state against constant mu_s
  (the same trajectory, no stick state), interleaved in this process.

    .venv/bin/python studies/measure_breakaway.py [repeats]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.contact3d.test_backlash import DEMO, _contact3d_worm_speed_rpm, _friction, _mu_at  # noqa: E402
from tests.results.test_trust import HOLD_FROM_REST, USER_GEAR, _assist, _breakaway_torque_nm  # noqa: E402

CONSTANT_MU_S = ["contact.friction_static=null", "contact.friction_dynamic=null", "contact.friction=0.09894"]
FRICTIONLESS = ["contact.friction_static=null", "contact.friction_dynamic=null", "contact.friction=0"]


def _run(template: Path, *sets: str):
    import wormsim
    from wormsim.scenario import load_scenario

    return wormsim.simulate(load_scenario(template, [*USER_GEAR, *HOLD_FROM_REST, *sets]))


def _worm_end_rpm(res) -> float:
    return float(res.series["worm_speed_rpm"][-1])


def holding(template: Path) -> dict:
    out = {}
    for ramp in ("0.002", "0.02"):
        for name, extra in (("stick_state", []), ("constant_mu_s", CONSTANT_MU_S)):
            s = _run(template, f"drive.ramp_s={ramp}", *extra).summary
            out[f"ramp_{ramp}_s_{name}"] = {"locked": s["locked"], "creep_speed_rpm": s["creep_speed_rpm"]}
    out["free_speed_rpm"] = abs(_worm_end_rpm(_run(template, "drive.ramp_s=0.002", *FRICTIONLESS)))
    return out


def assisted(template: Path, shares=(0.5, 1.1, 1.4, 2.0)) -> dict:
    from wormsim.scenario import load_scenario

    t_nm = _breakaway_torque_nm(load_scenario(template, [*USER_GEAR, *HOLD_FROM_REST, "drive.ramp_s=0.002"]))
    out: dict = {"breakaway_torque_hand_nm": t_nm}
    for k in shares:
        res = _run(template, "drive.ramp_s=0.002", *_assist(k * t_nm))
        out[f"share_{k}"] = {
            "locked": res.summary["locked"],
            "worm_end_rpm": abs(_worm_end_rpm(res)),
            "friction_coefficient_end": float(res.series["friction_coefficient"][-1]),
        }
    return out


def need(template: Path) -> dict:
    """need / limit on the hinge per sample while stuck (the Python samples, where the runner calls it)."""
    import wormsim.contact3d.flank_samples as FS
    import wormsim.contact3d.runner as R
    from wormsim.contact3d.breakaway import static_utilisation

    seen: list[tuple[float, float]] = []

    def recorded(m, d, dof):
        u = static_utilisation(m, d, dof)
        seen.append((float(d.time), u))
        return u

    FS.ENABLED, R.static_utilisation = False, recorded
    try:
        _run(template, "drive.ramp_s=0.002")
    finally:
        FS.ENABLED, R.static_utilisation = True, static_utilisation
    t, u = np.array(seen).T
    k = t > 0.0005
    return {"after_0.5_ms_min": float(u[k].min()), "after_0.5_ms_max": float(u[k].max()), "end": float(u[-1])}


def demo_ramps() -> dict:
    from meshgen.geometry import derive
    from wormsim.scenario import load_scenario

    g = derive(load_scenario(DEMO).gear)
    fr = _friction(_mu_at(g, +0.3), _mu_at(g, -0.3))
    out = {f"ramp_{r}_s_worm_end_rpm": _contact3d_worm_speed_rpm(fr, ramp_s=r) for r in (0.002, 0.001, 0.0005)}
    out["free_speed_rpm"] = _contact3d_worm_speed_rpm(_friction(0.0))
    return out


def cost(template: Path, repeats: int) -> dict:
    sets = ["drive.ramp_s=0.02", "simulation.duration_s=0.1"]
    us: dict[str, list[float]] = {"stick_state": [], "constant_mu_s": []}
    creep = {}
    _run(template, *sets)  # warm
    for _ in range(repeats):
        for name, extra in (("stick_state", []), ("constant_mu_s", CONSTANT_MU_S)):
            t0 = time.process_time()
            res = _run(template, *sets, *extra)
            us[name].append(1e6 * (time.process_time() - t0) / res.steps)
            creep[name] = res.summary["creep_speed_rpm"]
    out = {f"{k}_us_per_step": {"min": min(v), "median": statistics.median(v), "runs": v} for k, v in us.items()}
    out["same_creep"] = creep["stick_state"] == creep["constant_mu_s"]
    out["ratio_min"] = min(us["stick_state"]) / min(us["constant_mu_s"])
    out["ratio_median"] = statistics.median(us["stick_state"]) / statistics.median(us["constant_mu_s"])
    return out


def main(repeats: int = 8) -> None:
    from wormsim.cli.init import write_template
    from wormsim.results.provenance import record

    with tempfile.TemporaryDirectory() as tmp:
        template = write_template(Path(tmp) / "user_gear.yaml")
        data = {
            "user_gear_holding": holding(template),
            "user_gear_assisted": assisted(template),
            "user_gear_need_over_limit": need(template),
            "demo_gear_ramps": demo_ramps(),
            "cost": cost(template, repeats),
        }
    path = record("breakaway", data, f"studies/measure_breakaway.py {repeats}")
    print(path.read_text())


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 8)
