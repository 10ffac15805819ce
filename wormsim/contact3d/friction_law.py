"""The friction law mu(Vs) in compiled form, the one the runs use (Python sample loop and compiled samples alike):
wormsim.physics.friction.friction_coefficient_scalar's three forms with its operations, on five parameters
(`mu_params`)."""

from __future__ import annotations

import math

import numba

from wormsim.physics.friction import GROUPS, friction_coefficient
from wormsim.physics.units import DEG

CONSTANT, STEP, GROUP = 0.0, 1.0, 2.0  # mu_params' kind
STICK_RELEASE = 0.1  # stuck_after: a sliding pair sticks again below this fraction of v_stick


def mu_params(contact) -> tuple[float, float, float, float, float]:
    """(kind, a, b, c, deg) of the scenario's contact block: constant mu = a; STEP(|Vs|, 0, a = static, b = v_t,
    c = dynamic); friction group tan(deg / (a |Vs|^b + c)) (seed 000's rho(Vs), wormsim/physics/friction.py)."""
    if contact.friction_group is not None:
        a, b, c = GROUPS[contact.friction_group]
        return GROUP, float(a), float(b), float(c), DEG
    if contact.friction is None and contact.friction_static is None:
        return CONSTANT, float(friction_coefficient(contact, 0.0)), 0.0, 0.0, DEG
    if contact.friction is not None:
        return CONSTANT, float(contact.friction), 0.0, 0.0, DEG
    return (
        STEP,
        float(contact.friction_static),
        float(contact.transition_velocity_m_s),
        float(contact.friction_dynamic),
        DEG,
    )


@numba.njit(cache=True, inline="always")
def mu_at(vs, kind, a, b, c, deg):
    """mu at the sliding speed vs (mu_params' forms; STEP is wormsim.physics.units.step(|vs|, 0, a, b, c))."""
    if kind == CONSTANT:
        return a
    if kind == STEP:
        t, h0, t1, h1 = abs(vs), a, b, c
        if t1 <= 0.0:
            return h1 if t >= 0.0 else h0
        s = (t - 0.0) / (t1 - 0.0)
        s = 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)
        return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    return math.tan(deg / (a * abs(vs) ** b + c))


@numba.njit(cache=True, inline="always")
def stuck_after(stuck, vs, v_stick):
    """The stick state after a sample at the sliding speed vs (pre-sliding, as a static friction model's stick
    phase: the static coefficient holds until the slip breaks away): a stuck pair stays stuck while vs < v_stick
    and breaks away at vs >= v_stick; a sliding pair sticks again below STICK_RELEASE v_stick. While stuck, mu is
    mu(0) (mu_at(0.0, ...)), else mu(vs). v_stick <= 0: never stuck (mu(vs) throughout). contact3d runs with
    v_stick = contact.transition_velocity_m_s where the wheel drives a pair that self-locks at rest, starting stuck
    (wormsim.physics.locking.stick_velocity_m_s), and with 0 otherwise."""
    if v_stick <= 0.0:
        return False
    return vs < (v_stick if stuck else STICK_RELEASE * v_stick)


@numba.njit(cache=True)
def mu_of(vs, p):
    """mu_at with the parameters as one tuple (the Python sample loop's call)."""
    return mu_at(vs, p[0], p[1], p[2], p[3], p[4])
