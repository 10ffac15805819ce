"""Friction angle of the worm/wheel sliding contact, in SI (rad, m/s).

Seed 000 (`../shared/seeds/000_30b2fd31dd44c873.txt`, table "Approximated formulae for the sliding
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

The 3D contact model imports these functions too.
"""
from __future__ import annotations

import math

import numpy as np

from wormsim.units import DEG

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
        out = DEG / (a * vs ** b + c)
    return float(out) if out.ndim == 0 else out


def rho_static_rad(group: str | None = None, friction: float | None = None) -> float:
    """Static friction angle: rho at Vs = 0 (1/c deg for a group, atan(mu) for a constant mu)."""
    return rho_rad(0.0, group, friction)


def mu_from_rho(rho):
    """Coulomb coefficient mu = tan(rho)."""
    return np.tan(rho)
