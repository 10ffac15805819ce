"""Exceptions that the CLI maps to exit codes: ScenarioError exit 2, SimulationError exit 3.

Each guard of a run raises its own subclass of SimulationError, so that callers (the bench's stability edge)
sort failures by type, not by the wording of the message.
"""

__all__ = [
    "ScenarioError",
    "SimulationError",
    "DivergedError",
    "TeethJumpedError",
    "PenetrationError",
    "LockedError",
    "OverspeedError",
    "RingingError",
]


class ScenarioError(ValueError):
    """Invalid input: the message names the field, the value and what is allowed (exit code 2 at the CLI)."""


class SimulationError(RuntimeError):
    """The simulation failed (diverged, teeth jumped, locked when told to move...): exit 3.

    The message is a diagnosis that says what to change.
    """


class DivergedError(SimulationError):
    """Non-finite state, a huge acceleration, or a runaway above the stable timestep."""


class TeethJumpedError(SimulationError):
    """The transmission error passed half a pitch within the stable timestep: the load overpowers the mesh."""


class PenetrationError(SimulationError):
    """Penetration (contact3d) or mesh deflection (torsional) beyond 0.4 m_x: the teeth would skip."""


class LockedError(SimulationError):
    """A speed-driven drive held below half its command (self-locking back-drive, or a jammed mesh)."""


class OverspeedError(SimulationError):
    """The worm turns more per step than contact3d resolves: its pieces would pass through the wheel's."""


class RingingError(SimulationError):
    """A mass-scaled run rang: efficiency above 1 or kinetic energy far above its target share of the work."""
