"""The self-locking screw jack back-driven by its speed-driven wheel (tests/contact3d/test_guards.py, mu 0.2): per
sample, the contacts' elliptic-cone rows read after each step (docs/contact3d.md, "Friction against the slip"):
count, normal force sum, deepest contact, friction utilisation |f_t| / (mu f_n), the worm torque from the normal rows
and from the friction rows apart, cos(f_t, -v_t), and the friction rows' reference acceleration |a_ref_t| against
the contacts' tangential acceleration |J_t qacc| (medians over the contacts). The friction guard is switched off
(its hold set beyond the run) so the run shows what it stopped.

    .venv/bin/python studies/measure_lock_friction.py [flanks|pieces] [mu] [duration_s]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.contact3d.test_guards import WHEEL_DRIVEN  # noqa: E402  (the screw jack with its wheel speed-driven)


def contact_rows(m: mujoco.MjModel, d: mujoco.MjData, worm_dof: int) -> dict:
    """The quantities of the module docstring at the current step."""
    jw = m.dof_jntid[worm_dof]
    axis, anchor = d.xaxis[jw], d.xanchor[jw]
    jq = np.zeros(d.nefc)
    if d.nefc:
        mujoco.mj_mulJacVec(m, d, jq, d.qacc)
    fn = util = tn = tf = 0.0
    cos, aref, jacc, util = [], [], [], []
    depth = 0.0
    for c in range(d.ncon):
        a, dim = d.contact.efc_address[c], d.contact.dim[c]
        if a < 0 or dim < 3:
            continue
        fr = d.contact.frame[c].reshape(3, 3)
        f, v = d.efc_force[a : a + 3], d.efc_vel[a : a + 3]
        r = d.contact.pos[c] - anchor
        tn += np.dot(np.cross(r, -f[0] * fr[0]), axis)  # the force on the worm is minus the wheel's
        tf += np.dot(np.cross(r, -(f[1] * fr[1] + f[2] * fr[2])), axis)
        fn += f[0]
        depth = max(depth, -d.contact.dist[c])
        ft, vt = np.hypot(f[1], f[2]), np.hypot(v[1], v[2])
        if f[0] > 0:
            util.append(ft / (d.contact.friction[c][0] * f[0]))
        if ft > 0 and vt > 0:
            cos.append(-(f[1] * v[1] + f[2] * v[2]) / (ft * vt))
        aref.append(np.hypot(*d.efc_aref[a + 1 : a + 3]))
        jacc.append(np.hypot(*jq[a + 1 : a + 3]))
    med = lambda x: float(np.median(x)) if x else float("nan")  # noqa: E731
    return dict(
        n=len(aref), fn=fn, depth_um=depth * 1e6, util=med(util), worm_torque_normal=tn, worm_torque_friction=tf,
        cos=med(cos), aref=med(aref), jacc=med(jacc),
    )  # fmt: skip


def main(geometry: str = "flanks", mu: float = 0.2, duration_s: float = 0.085) -> None:
    from wormsim.contact3d import friction_guard
    from wormsim.contact3d.guards import Guards as _Guards
    from wormsim.contact3d.runner import simulate
    from wormsim.exceptions import SimulationError
    from wormsim.scenario import load_scenario

    friction_guard.HOLD_S = 1e9
    sets = WHEEL_DRIVEN + [f"contact.friction={mu}", f"simulation.duration_s={duration_s}"]
    sc = load_scenario(ROOT / "scenarios" / "screw_jack.yaml", sets + [f"contact.geometry={geometry}"])
    state = _Guards.state
    every = [0]

    def logged(self, d, t, th1, th2, w1, w2):
        every[0] += 1
        if every[0] % 100 == 0:
            r = contact_rows(self.bm.model, d, self.bm.worm_dof)
            print(
                f"t={t:.4f} worm {w1 * 9.549:7.1f} rpm wheel {w2 * 9.549:6.2f} rpm contacts {r['n']:3d} "
                f"f_n {r['fn'] / 1e3:8.1f} kN depth {r['depth_um']:6.1f} um util {r['util']:.2f} "
                f"T_worm normal {r['worm_torque_normal']:8.2f} friction {r['worm_torque_friction']:8.2f} N m "
                f"cos {r['cos']:+.2f} |a_ref_t| {r['aref']:.3g} |J_t qacc| {r['jacc']:.3g}",
                flush=True,
            )
        return state(self, d, t, th1, th2, w1, w2)

    _Guards.state = logged
    try:
        simulate(sc)
        print("ran to the end")
    except SimulationError as e:
        print(f"{type(e).__name__}: {e}")


if __name__ == "__main__":
    a = sys.argv[1:]
    main(a[0] if a else "flanks", float(a[1]) if len(a) > 1 else 0.2, float(a[2]) if len(a) > 2 else 0.085)
