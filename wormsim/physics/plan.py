"""The plan of a gear-level run (torsional, contact3d): what the run derives from its scenario, built once by
`gear_plan` and handed down; after it is built no helper of the run reads the scenario.

It holds the gear's geometry (SI), the drive and load (gear_theory.Duty: their commands, ramps, lock-check start and
working flank), the friction values the levels size things by (mu at rest and at 1 m/s, rho' at rest, the friction
mode), the working loads (the working wheel torque, the drive's expected torque and a speed drive's servo gain), the
commanded worm speed, whether a speed-driven wheel back-drives a pair that self-locks at rest
(wormsim.physics.locking), the friction law's stick state, the displaced pair of the errors: block, and the typed
blocks the levels' own derivations take whole (contact:, materials:, simulation:, errors:, shafts:). Error messages
take what they quote from it (the load's torque and ramp).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from meshgen.displaced import Deviations
from meshgen.geometry import GearGeometry
from meshgen.kinematic_tca import KinematicTCA
from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import friction_coefficient, friction_mode, mu_varies
from wormsim.physics.geometry import derive, displaced_pair
from wormsim.physics.locking import backdrive_self_locks, stick_velocity_m_s
from wormsim.scenario import Contact, Errors, Materials, Scenario, ScenarioError, Shafts, Simulation

NOMINAL_SLIDING_SPEED_M_S = 1.0  # the speed servo's expected torque takes the friction coefficient at Vs = 1 m/s


@dataclass(frozen=True)
class GearPlan:
    """A gear-level run's plan (module docstring)."""

    name: str  # the scenario's name (summary key `scenario`, the MuJoCo model's name)
    model: str  # the fidelity level
    geometry: GearGeometry
    duty: gt.Duty
    contact: Contact
    materials: Materials
    simulation: Simulation
    errors: Errors
    shafts: Shafts | None
    mu_static: float  # friction_coefficient at Vs = 0
    mu_nominal: float  # friction_coefficient at NOMINAL_SLIDING_SPEED_M_S
    rho_static_rad: float  # rho' = atan(mu_static / cos alpha_n) (gear_theory.virtual_friction_angle_rad)
    friction_mode: str  # wormsim.physics.friction.friction_mode
    working_wheel_torque_nm: float  # gear_theory.working_wheel_torque_of
    drive_torque_nm: float  # gear_theory.expected_drive_torque_of at mu_nominal
    servo_gain_nm_s: float | None  # gear_theory.servo_gain_of; None for a torque drive
    worm_speed_rad_s: float | None  # gear_theory.worm_speed_command_rad_s; None for a torque drive
    backdrive_self_locks: bool  # wormsim.physics.locking: a speed-driven wheel against a pair self-locking at rest
    stick_velocity_m_s: float  # the friction law's stick state (wormsim.physics.locking.stick_velocity_m_s); 0: none

    @property
    def transition_velocity_m_s(self) -> float:
        """contact.transition_velocity_m_s: static friction's reach in sliding speed."""
        return self.contact.transition_velocity_m_s

    @functools.cached_property
    def displaced(self) -> tuple[Deviations, KinematicTCA] | None:
        """The errors: block's displaced pair (wormsim.physics.geometry.displaced_pair); None for the perfect pair."""
        return displaced_pair(self.errors, self.geometry)


def gear_plan(scenario: Scenario, geometry: GearGeometry | None = None) -> GearPlan:
    """The GearPlan of a gear-level scenario (a gear: and a drive: block); geometry: derive(scenario.gear) unless
    given."""
    if scenario.gear is None:
        raise ScenarioError(f"gear: model {scenario.model} needs a gear: block")
    g = geometry if geometry is not None else derive(scenario.gear)
    duty = gt.duty(scenario, g.hand)
    drv, load, c = duty.drive, duty.load, scenario.contact
    mu0 = float(friction_coefficient(c, 0.0))
    mu1 = float(friction_coefficient(c, NOMINAL_SLIDING_SPEED_M_S))
    rho0 = gt.virtual_friction_angle_rad(mu0, g.alpha_n)
    t_drive = gt.expected_drive_torque_of(drv, load, g.ratio, g.gamma_m, g.alpha_n, mu1)
    return GearPlan(
        name=scenario.name,
        model=scenario.model,
        geometry=g,
        duty=duty,
        contact=c,
        materials=scenario.materials,
        simulation=scenario.simulation,
        errors=scenario.errors,
        shafts=scenario.shafts,
        mu_static=mu0,
        mu_nominal=mu1,
        rho_static_rad=rho0,
        friction_mode=friction_mode(c),
        working_wheel_torque_nm=gt.working_wheel_torque_of(drv, load, g.ratio),
        drive_torque_nm=t_drive,
        servo_gain_nm_s=gt.servo_gain_of(drv, t_drive) if duty.speed_driven else None,
        worm_speed_rad_s=gt.worm_speed_command_rad_s(drv, g.ratio),
        backdrive_self_locks=backdrive_self_locks(drv, g.gamma_m, rho0),
        stick_velocity_m_s=stick_velocity_m_s(drv, g.gamma_m, rho0, c.transition_velocity_m_s, mu_varies(c)),
    )
