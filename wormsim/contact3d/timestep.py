"""contact3d's timestep, chosen once before the model is built (choose_timestep) and passed to it.

Two limits bind: the contact spring-damper's explicit stability limit (ContactLaw.stable_limit_s, three tooth pairs'
contacts in parallel; the default is 0.4 x it, rounded down to two significant digits), and the worm's rotation per
step: contact3d resolves at most MAX_WORM_TURN_PER_STEP_RAD (beyond it the thread's convex pieces pass through the
wheel's between steps; docs/stability_speed.md). A scenario timestep above the speed limit is refused (ScenarioError
naming simulation.timestep_s and its allowed range); one above the stable limit is left to the divergence guard, whose
message names that limit. simulation.speculative does not prevent tunnelling (measured: it fails earlier).
"""

from __future__ import annotations

from meshgen.geometry import GearGeometry
from wormsim.contact3d.law import ContactLaw
from wormsim.contact3d.mass_scaling import SCALED_STEP_FRACTION, floor_2_digits
from wormsim.physics.gear_theory import duty, round_down_125, worm_speed_command_rad_s
from wormsim.physics.units import rad_s_to_rpm
from wormsim.scenario import Scenario, ScenarioError

DEFAULT_FRACTION = (
    0.4  # default timestep: this fraction of the stable limit, rounded down to two digits (decision 0043)
)
MAX_WORM_TURN_PER_STEP_RAD = 0.035  # largest worm rotation per step contact3d resolves (2.0 deg;
# docs/stability_speed.md has the measurements behind it)
OVERSPEED_GUARD = 1.25  # the running check fires at this multiple of MAX_WORM_TURN_PER_STEP_RAD
DEFAULT_SOURCE = "default: 0.4 x the stable limit, rounded down to two digits (docs/bench.md, stability map)"
SHAFTS_SOURCE = (
    "default: 0.4 x the shafts' stable limit (their stiffest mode, below the contact's), rounded down to two digits "
    "(wormsim.contact3d.shafts)"
)


def default_timestep(law: ContactLaw, contacts: int | None = None) -> float:
    """DEFAULT_FRACTION x the explicit stability limit with `contacts` in parallel (default: three tooth pairs'
    worth, ContactLaw.stable_limit_s), rounded down to two significant digits (mass_scaling.floor_2_digits: 1-2-5 lost
    up to 2.5x of the step; every h <= 0.4 x the limit met decision 0006's criteria, docs/data/step_convergence.json,
    study "fraction 0.4 of the limit, 2 digits"; decision 0043)."""
    limit = law.stable_limit_s if contacts is None else law.stable_timestep_s(contacts)
    return floor_2_digits(DEFAULT_FRACTION * limit)


def speed_timestep_limit_s(w1_rad_s: float) -> float:
    """Largest timestep at worm speed w1: h <= MAX_WORM_TURN_PER_STEP_RAD / w1."""
    return MAX_WORM_TURN_PER_STEP_RAD / w1_rad_s


def choose_timestep(
    scenario: Scenario, geo: GearGeometry, law: ContactLaw, mass_scaling: float = 1.0
) -> tuple[float, str]:
    """timestep_for the scenario's simulation.timestep_s and its drive's worm speed
    (gear_theory.worm_speed_command_rad_s)."""
    w1 = worm_speed_command_rad_s(duty(scenario, geo.hand).drive, geo.ratio)
    return timestep_for(scenario.simulation.timestep_s, w1, law, mass_scaling)


def timestep_for(h: float | None, w1: float | None, law: ContactLaw, mass_scaling: float = 1.0) -> tuple[float, str]:
    """(timestep, timestep_source): h, the scenario's simulation.timestep_s (checked against the speed limit at the
    commanded worm speed w1, None for a torque drive), else the contact's default unless w1 needs a smaller one: then
    the speed limit rounded down to 1-2-5. A mass-scaled run (mass_scaling > 1; `law` is then the scaled one) defaults
    to SCALED_STEP_FRACTION of the scaled stable limit, rounded down to two digits (wormsim.contact3d.mass_scaling)."""
    if h is not None:
        # above the contact's stable limit the divergence guard's diagnosis (which names that limit) comes first
        if h <= law.stable_limit_s and w1 is not None and w1 * h > MAX_WORM_TURN_PER_STEP_RAD:
            lim = speed_timestep_limit_s(w1)
            raise ScenarioError(
                f"simulation.timestep_s = {h:.3g} s is too large for the worm speed {rad_s_to_rpm(w1):.0f} rpm: the "
                f"worm would turn {w1 * h:.3g} rad per step, contact3d resolves at most {MAX_WORM_TURN_PER_STEP_RAD} "
                f"rad (beyond it the thread passes through the wheel's teeth between steps); allowed range: 0 < "
                f"simulation.timestep_s <= {lim:.3g} s, or leave it unset (the default then follows the speed). "
                f"simulation.speculative does not prevent it (measured: it tunnels sooner, docs/stability_speed.md)"
            )
        return h, "scenario"
    h, source = default_timestep(law), DEFAULT_SOURCE
    if mass_scaling > 1:
        h = floor_2_digits(SCALED_STEP_FRACTION * law.stable_limit_s)
        source = (
            f"mass scaling x {mass_scaling:g}: {SCALED_STEP_FRACTION} x the scaled stable limit, rounded down to "
            f"two digits (docs/contact3d.md, 'Mass scaling')"
        )
    if w1 is not None and w1 * h > MAX_WORM_TURN_PER_STEP_RAD:
        return round_down_125(speed_timestep_limit_s(w1)), (
            f"worm speed: {rad_s_to_rpm(w1):.0f} rpm needs <= {MAX_WORM_TURN_PER_STEP_RAD} rad of worm rotation "
            f"per step, rounded down to 1-2-5 (below the contact's default; docs/stability_speed.md)"
        )
    return h, source
