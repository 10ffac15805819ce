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
"""

from __future__ import annotations

import math

import numpy as np

from wormsim.physics.units import DEG, step
from wormsim.scenario import Contact

DEFAULT_FRICTION = 0.05

# group -> (a, b, c) of rho(Vs) = 1 / (a Vs^b + c) deg, Vs in m/s (seed 000)
GROUPS: dict[str, tuple[float, float, float]] = {
    "I": (0.256, 0.591, 0.151),
    "II": (0.174, 0.642, 0.140),
    "III": (0.161, 0.535, 0.088),
}


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
        out = DEG / (a * vs**b + c)
    return float(out) if out.ndim == 0 else out


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
    """mu(Vs): see the module docstring. Vectorised over Vs."""
    vs = np.abs(np.asarray(sliding_speed_m_s, dtype=float))
    if contact.friction_group is not None:
        out = mu_from_rho(rho_rad(vs, group=contact.friction_group))
    elif contact.friction_static is not None:
        out = step(vs, 0.0, contact.friction_static, contact.transition_velocity_m_s, contact.friction_dynamic)
    elif contact.friction is not None:
        out = np.full_like(vs, contact.friction)
    else:
        out = np.full_like(vs, DEFAULT_FRICTION)
    return float(out) if np.ndim(out) == 0 else out


def friction_coefficient_scalar(contact: Contact):
    """A float-only mu(Vs) equal to friction_coefficient (fast per step: the torsional ODE's right-hand side and
    contact3d's runner)."""
    if contact.friction_group is not None or (contact.friction is None and contact.friction_static is None):
        mu_c = None if contact.friction_group is not None else float(friction_coefficient(contact, 0.0))
        if mu_c is not None:
            return lambda vs: mu_c
        a, b, c = GROUPS[contact.friction_group]
        return lambda vs: math.tan(DEG / (a * abs(vs) ** b + c))
    if contact.friction is not None:
        mu_c = float(contact.friction)
        return lambda vs: mu_c
    ms, md, vt = contact.friction_static, contact.friction_dynamic, contact.transition_velocity_m_s
    return lambda vs: step(abs(vs), 0.0, ms, vt, md)
