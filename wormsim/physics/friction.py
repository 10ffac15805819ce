"""Friction angle of the worm/wheel sliding contact, in SI (rad, m/s).

Seed 000 (the two-sided wedge model's document, README "Seeds"; its table "Approximated formulae for the sliding
friction angle"): for three steel-worm / bronze-wheel material groups the friction angle, in
DEGREES, is a fit to experimental data over the sliding speed Vs in m/s:

    rho(Vs) = 1 / (a Vs^b + c)   [deg]

    group I   (worm HRC > 48,       wheel bronze Sn 6-7 %, Ni 1-2 %):  a 0.256, b 0.591, c 0.151
    group II  (worm 32 < HRC < 48,  wheel bronze Sn 6-10 %):           a 0.174, b 0.642, c 0.140
    group III (worm HRC > 48,       wheel bronze Fe 1 %):              a 0.161, b 0.535, c 0.088

rho is largest at standstill, rho(0) = 1/c (6.6, 7.1 and 11.4 deg), which we take as the static
friction angle. The fit is even in Vs: we evaluate it at |Vs| (the seed's code raises a negative
speed to a fractional power, which is not real).

A constant Coulomb coefficient mu gives rho = atan(mu) at every speed.

The scenario's `contact:` friction keys select mu(Vs) (friction_coefficient, shared by torsional and contact3d):
  friction: mu                           constant
  friction_static/_dynamic: mu(Vs) = STEP(|Vs|, 0, mu_s, v_t, mu_d)   (ADAMS-style cubic blend over
                                          the transition velocity v_t = contact.transition_velocity_m_s)
  friction_group: mu(Vs) = tan(rho(Vs)), rho of seed 000 above
  none given: mu = 0.05 (lubricated steel/bronze, DEFAULT_FRICTION).

The law is written once, compiled (`mu_at`, on the four numbers of `mu_law`; `rho_group_rad` the group's rho(Vs)):
the compiled contact3d samples call it, friction_coefficient and rho_rad are its numpy forms (numba.vectorize, built
on the first array; one speed calls the compiled function),
friction_coefficient_scalar a float wrapper (the torsional ODE, contact3d's Python samples, wormsim.pair).
Group I against a handbook curve (Mechanical Engineer's Data Handbook, p. 111, hard steel on phosphor bronze:
mu 0.06 / 0.05 / 0.035 / 0.023 / 0.017 / 0.014 at 0.5 / 1 / 2 / 5 / 10 / 20 m/s): within 25 %
(tests/physics/test_friction.py).
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numba
import numpy as np

from wormsim.physics.units import DEG
from wormsim.scenario import Contact

DEFAULT_FRICTION = 0.05

# group -> (a, b, c) of rho(Vs) = 1 / (a Vs^b + c) deg, Vs in m/s (seed 000)
GROUPS: dict[str, tuple[float, float, float]] = {
    "I": (0.256, 0.591, 0.151),
    "II": (0.174, 0.642, 0.140),
    "III": (0.161, 0.535, 0.088),
}


CONSTANT, STEP, GROUP = 0.0, 1.0, 2.0  # MuLaw's kind


class MuLaw(NamedTuple):
    """mu(Vs) as four numbers: constant mu = a; STEP(|Vs|, 0, a = static, b = v_t, c = dynamic); friction group
    tan(rho(Vs)), rho = 1 / (a |Vs|^b + c) deg."""

    kind: float
    a: float
    b: float
    c: float


@numba.njit(cache=True, inline="always")
def rho_group_rad(vs, a, b, c):
    """rho(Vs) = 1 / (a |Vs|^b + c) deg of a friction group, in rad (module docstring, seed 000)."""
    return DEG / (a * abs(vs) ** b + c)


@numba.njit(cache=True, inline="always")
def mu_at(vs, kind, a, b, c):
    """mu at the sliding speed vs (MuLaw's forms; STEP is wormsim.physics.units.step(|vs|, 0, a, b, c))."""
    if kind == CONSTANT:
        return a
    if kind == STEP:
        t, h0, t1, h1 = abs(vs), a, b, c
        if t1 <= 0.0:
            return h1 if t >= 0.0 else h0
        s = (t - 0.0) / (t1 - 0.0)
        s = 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)
        return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    return math.tan(rho_group_rad(vs, a, b, c))


STICK_RELEASE = 0.1  # stuck_after: a sliding pair sticks again below this fraction of v_stick
BREAKAWAY = 1.0  # stuck_after: a stuck pair breaks away where the friction it needs reaches this share of mu_s f_n


@numba.njit(cache=True, inline="always")
def stuck_after(stuck, vs, v_stick, utilisation):
    """The stick state after a sample at the sliding speed vs (a static friction model's stick phase: the static
    coefficient holds until the friction the pair needs reaches the static limit, Coulomb's break-away): a stuck pair
    stays stuck while `utilisation`, the friction it needs over mu(0) times its normal forces, is below BREAKAWAY, and
    breaks away at BREAKAWAY (contact3d: wormsim.contact3d.breakaway.static_utilisation, on the worm's hinge, whatever
    the slip speed; docs/decisions/0058-breakaway-on-static-friction.md); a sliding pair sticks again below
    STICK_RELEASE v_stick (utilisation is not used). While stuck, mu is mu(0) (mu_at(0.0, ...)), else mu(vs).
    v_stick <= 0: never stuck (mu(vs) throughout). contact3d runs with v_stick = contact.transition_velocity_m_s where
    the wheel drives a pair that self-locks at rest, starting stuck (wormsim.physics.locking.stick_velocity_m_s), and
    with 0 otherwise."""
    if v_stick <= 0.0:
        return False
    if stuck:
        return utilisation < BREAKAWAY
    return vs < STICK_RELEASE * v_stick


@numba.njit(cache=True)
def mu_of(vs, law):
    """mu_at with the law as one tuple (MuLaw)."""
    return mu_at(vs, law[0], law[1], law[2], law[3])


@functools.cache
def _ufuncs():
    """(mu_at, rho_group_rad) as numpy ufuncs (numba.vectorize: the same definitions), built on first use."""
    mu = numba.vectorize(["float64(float64, float64, float64, float64, float64)"], cache=True)(mu_at.py_func)
    rho = numba.vectorize(["float64(float64, float64, float64, float64)"], cache=True)(rho_group_rad.py_func)
    return mu, rho


def mu_law(contact: Contact) -> MuLaw:
    """The scenario's contact block's mu(Vs) (module docstring)."""
    if contact.friction_group is not None:
        a, b, c = GROUPS[contact.friction_group]
        return MuLaw(GROUP, float(a), float(b), float(c))
    if contact.friction_static is not None:
        v_t = float(contact.transition_velocity_m_s)
        return MuLaw(STEP, float(contact.friction_static), v_t, float(contact.friction_dynamic))
    mu = DEFAULT_FRICTION if contact.friction is None else contact.friction
    return MuLaw(CONSTANT, float(mu), 0.0, 0.0)


def mu_varies(contact: Contact) -> bool:
    """mu depends on the sliding speed (a static/dynamic pair or a friction group; not a constant mu)."""
    return mu_law(contact).kind != CONSTANT


def rho_rad(vs_m_s, group: str | None = None, friction: float | None = None):
    """Friction angle rho(Vs) in rad for material `group` (I, II, III) or a constant `friction`.

    Exactly one of `group` / `friction` is given. Vectorised over `vs_m_s` (float in, float out;
    array in, array out); the sign of the sliding speed does not matter.
    """
    if (group is None) == (friction is None):
        raise ValueError("give exactly one of group / friction")
    vs = np.abs(np.asarray(vs_m_s, dtype=float))
    if friction is not None:
        out = np.full_like(vs, math.atan(friction))
    else:
        try:
            a, b, c = GROUPS[group]
        except KeyError:
            raise ValueError(f"friction group {group!r}: allowed I, II, III") from None
        if vs.ndim == 0:  # one speed: the compiled law itself (friction_coefficient)
            return float(rho_group_rad(float(vs), a, b, c))
        out = _ufuncs()[1](vs, a, b, c)
    return float(out) if np.ndim(out) == 0 else out


def rho_static_rad(group: str | None = None, friction: float | None = None) -> float:
    """Static friction angle: rho at Vs = 0 (1/c deg for a group, atan(mu) for a constant mu)."""
    return rho_rad(0.0, group, friction)


def mu_from_rho(rho):
    """Coulomb coefficient mu = tan(rho)."""
    return np.tan(rho)


def friction_mode(contact: Contact) -> str:
    if contact.friction_group is not None:
        return f"group {contact.friction_group} (seed 000 rho(Vs))"
    if contact.friction_static is not None:
        return (
            f"static {contact.friction_static} -> dynamic {contact.friction_dynamic} "
            f"over {contact.transition_velocity_m_s} m/s"
        )
    if contact.friction is not None:
        return f"constant {contact.friction}"
    return f"default constant {DEFAULT_FRICTION}"


def friction_coefficient(contact: Contact, sliding_speed_m_s) -> float | np.ndarray:
    """mu(Vs): see the module docstring (mu_at). Vectorised over Vs."""
    vs = np.abs(np.asarray(sliding_speed_m_s, dtype=float))
    if vs.ndim == 0:  # one speed (gear_plan's mu, the wedge's): the compiled law itself, the same bits as the ufunc
        # (tests/physics/test_friction.py); it loads one cached function where the ufuncs load two (about 0.1 s of
        # CPU in a process's first run, on a sweep's fork server's path before the first point)
        return float(mu_at(float(vs), *mu_law(contact)))
    return _ufuncs()[0](vs, *mu_law(contact))


def friction_coefficient_scalar(contact: Contact):
    """A float-only mu(Vs) equal to friction_coefficient (fast per step: the torsional ODE's right-hand side and
    contact3d's runner): mu_at on the contact's MuLaw."""
    kind, a, b, c = mu_law(contact)
    if kind == CONSTANT:
        return lambda vs: a
    return lambda vs: mu_at(vs, kind, a, b, c)
