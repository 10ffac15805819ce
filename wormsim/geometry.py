"""The simulator's edge to meshgen: gear geometry and collision pieces for a scenario, with meshgen's GeometryError
turned into ScenarioError (exit 2; the message already names the `gear:` field)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from meshgen import geometry as _geometry
from meshgen import pieces as _pieces
from meshgen.geometry import GearData, GearGeometry, GeometryError
from meshgen.pieces import GearSet
from wormsim.scenario import Scenario, ScenarioError


@contextmanager
def geometry_errors() -> Iterator[None]:
    """meshgen's GeometryError as ScenarioError (invalid input)."""
    try:
        yield
    except GeometryError as exc:
        raise ScenarioError(str(exc)) from None


def derive(gear: GearData) -> GearGeometry:
    """meshgen.geometry.derive, raising ScenarioError on impossible gear data."""
    with geometry_errors():
        return _geometry.derive(gear)


def gear_set(scenario: Scenario, resolution: str | None = None) -> tuple[GearGeometry, GearSet]:
    """(geometry, collision pieces) of the scenario's gear at `resolution` (default: simulation.resolution)."""
    if scenario.gear is None:
        raise ScenarioError("gear: this needs a gear: block (model contact3d or torsional)")
    geo = derive(scenario.gear)
    with geometry_errors():
        return geo, _pieces.build_gear_set(geo, resolution=resolution or scenario.simulation.resolution)
