"""Exceptions that the CLI maps to exit codes (INTERFACE.md)."""
from wormsim.scenario import ScenarioError  # noqa: F401  (exit 2: invalid input)


class SimulationError(RuntimeError):
    """The simulation failed (diverged, teeth jumped, locked when told to move...): exit 3.

    The message is a diagnosis that says what to change.
    """
