"""The messages of the run's guards (wormsim.contact3d.guards): each builds its SimulationError subclass
(wormsim.exceptions) with the diagnosis and what to change."""

from __future__ import annotations

import math

from wormsim.contact3d.mjcf import BuiltModel
from wormsim.contact3d.timestep import MAX_WORM_TURN_PER_STEP_RAD, default_timestep, speed_timestep_limit_s
from wormsim.exceptions import (
    DivergedError,
    LockedError,
    OverspeedError,
    PenetrationError,
    SimulationError,
    TeethJumpedError,
)
from wormsim.physics.units import rad_s_to_rpm

JUMP_PITCH = 0.5  # transmission error (in pitches) that counts as teeth jumping


def diverged_error(t: float, dt: float, bm: BuiltModel, what: str) -> SimulationError:
    """Divergence diagnosis. Above the explicit stability limit of the contact spring-damper with three pairs in
    parallel (ContactLaw.stable_timestep_s: h < 2/omega (sqrt(1 + zeta^2) - zeta)) the cure is the timestep: the
    message names the limit and wormsim's default (wormsim.contact3d.timestep.default_timestep, 0.4 x the limit
    rounded down to 1-2-5). Within the limit the blow-up comes from a command step the light shafts cannot follow."""
    lim = bm.law.stable_limit_s
    h0 = default_timestep(bm.law)
    if dt > lim:
        return DivergedError(
            f"diverged at t = {t:.4g} s ({what}): timestep {dt:.3g} s is above the contact's stable limit "
            f"{lim:.3g} s (contact stiffness {bm.law.pair_stiffness_n_per_m:.3g} N/m per tooth pair); set "
            f"simulation.timestep_s <= {h0:.3g} s (the default for this contact: leave it unset) or lower "
            f"contact.stiffness_n_per_m"
        )
    return DivergedError(
        f"diverged at t = {t:.4g} s ({what}) at timestep {dt:.3g} s, within the contact's stable limit {lim:.3g} s: "
        f"a torque or speed step the light shafts cannot follow; lengthen drive.ramp_s / load.ramp_s, lower "
        f"load.torque_nm"
    )


def jump_error(t: float, te_pitch: float, dt: float, bm: BuiltModel) -> SimulationError:
    """Transmission error beyond half a pitch. Above the stable timestep this is the integration running away
    (reported as divergence: a stiffer contact would make it worse); within it the teeth really passed each
    other: the load overpowers the mesh. With contact.geometry flanks (the working flanks only: no tips, edges or
    roots) the jump itself is not modelled, and the message says so."""
    lim = bm.law.stable_limit_s
    if dt > lim:
        return diverged_error(t, dt, bm, f"the transmission error ran away to {te_pitch:.2f} pitch")
    flanks_note = (
        "; contact.geometry flanks models the working flanks only (no tips or edges), so the jump itself is not "
        "simulated: contact.geometry pieces models it"
        if bm.plan.flanks
        else ""
    )
    load = bm.plan.duty.load
    return TeethJumpedError(
        f"teeth jumped a pitch at t = {t:.4g} s (transmission error {te_pitch:.2f} pitch) at timestep {dt:.3g} s, "
        f"within the contact's stable limit {lim:.3g} s: the load overpowers the mesh (load {load.torque_nm} "
        f"N m over {load.ramp_s} s, contact stiffness {bm.law.pair_stiffness_n_per_m:.3g} N/m per tooth "
        f"pair); lower load.torque_nm or lengthen load.ramp_s, or raise contact.stiffness_n_per_m (with a smaller "
        f"simulation.timestep_s){flanks_note}"
    )


def overspeed_error(t: float, w1: float, dt: float, bm: BuiltModel) -> SimulationError:
    """The worm turns more than OVERSPEED_GUARD x MAX_WORM_TURN_PER_STEP_RAD per step (a torque drive running away,
    or a timestep set past the speed check): its pieces would pass through the wheel's between steps. A torque drive
    above the torque the load takes (the plan's expected drive torque, gear_theory.expected_drive_torque_of: T2 /
    (i eta) on the worm) runs away, and the message says so first: a smaller timestep only lets it run further."""
    lim = speed_timestep_limit_s(abs(w1))
    runaway = ""
    gp = bm.plan.gear
    drv = gp.duty.drive if gp is not None else None
    if gp is not None and drv is not None and drv.torque_nm is not None and abs(drv.torque_nm) > gp.drive_torque_nm:
        runaway = (
            f"runaway: the torque drive {abs(drv.torque_nm):.4g} N m on the {drv.on} exceeds the "
            f"{gp.drive_torque_nm:.3g} N m the load takes at full load (T_load and the wedge efficiency, DIN 3975-2), "
            "so the pair accelerates without bound; lower drive.torque_nm or use a speed drive (drive.speed_rpm). "
        )
    return OverspeedError(
        f"{runaway}worm overspeed at t = {t:.4g} s: the worm turns {rad_s_to_rpm(abs(w1)):.0f} rpm, "
        f"{abs(w1) * dt:.3g} rad per step of {dt:.3g} s, beyond the {MAX_WORM_TURN_PER_STEP_RAD} rad contact3d "
        "resolves (the thread passes through the wheel's teeth between steps); set simulation.timestep_s <= "
        f"{lim:.3g} s (or leave it unset for a speed-driven worm), or lower the drive (drive.speed_rpm / "
        "drive.torque_nm); simulation.speculative does not prevent it (measured: it tunnels sooner, "
        "docs/stability_speed.md)"
    )


def locked_error(t: float, w_drive: float, w_cmd: float, bm: BuiltModel) -> SimulationError:
    """A speed-driven drive held below half its command. When the wheel drives and the pair is self-locking at
    standstill, rho' = atan(mu_static / cos alpha_n) >= gamma (DIN 3975: back-driving efficiency
    tan(gamma - rho') / tan(gamma) <= 0), the diagnosis says so; otherwise the mesh is jammed."""
    geo, gp = bm.geometry, bm.plan.gear
    head = (
        f"the drive locked at t = {t:.4g} s: the {gp.duty.drive.on} turns at {rad_s_to_rpm(w_drive):.3g} rpm "
        f"against a command of {rad_s_to_rpm(w_cmd):.3g} rpm"
    )
    mu0, rho = gp.mu_static, gp.rho_static_rad
    if gp.duty.drive.on == "wheel" and rho >= geo.gamma_m:
        mu_max = math.tan(geo.gamma_m) * math.cos(geo.alpha_n)
        return LockedError(
            f"{head}: the pair is self-locking (rho' = atan(mu / cos alpha_n) = {math.degrees(rho):.2f} deg at "
            f"standstill friction mu = {mu0:.3g} >= lead angle gamma = {math.degrees(geo.gamma):.2f} deg), so the "
            f"wheel cannot turn the worm; drive the worm (drive.on=worm, load.on=wheel), or, to back-drive, lower "
            f"the friction below mu = tan(gamma) cos(alpha_n) = {mu_max:.3g} or raise gear.lead_angle_deg above "
            f"{math.degrees(rho):.2f} deg"
        )
    return LockedError(
        f"{head}: the mesh is jammed; check gear.backlash_mm, the load torque {gp.duty.load.torque_nm} N m "
        f"against what the drive can deliver, and the friction"
    )


def penetration_error(t: float, pen: float, pen_lim: float, dt: float, bm: BuiltModel) -> SimulationError:
    """Penetration beyond gear_theory.penetration_limit_m (0.4 m_x): the teeth are about to skip. Above the stable
    timestep this is the integration running away, reported as divergence with the timestep's cure (as jump_error):
    which guard sees the run-away first depends on the contacts' count and weights, not on its cause."""
    if dt > bm.law.stable_limit_s:
        return diverged_error(t, dt, bm, f"penetration {pen * 1e6:.1f} um beyond the tolerance {pen_lim * 1e6:.1f} um")
    return PenetrationError(
        f"penetration {pen * 1e6:.1f} um at t = {t:.4g} s exceeds the tolerance {pen_lim * 1e6:.1f} um "
        f"(0.4 m_x): contact too soft for the load or timestep {dt:.3g} s too large (stable limit "
        f"~{bm.law.stable_limit_s:.2g} s); raise contact.stiffness_n_per_m, lower simulation.timestep_s or lower "
        f"load.torque_nm"
    )
