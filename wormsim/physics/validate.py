"""Checks of a scenario beyond its schema that need no simulation: the ones `wormsim check` shares with
`mesh` and `run` (derived dimensions, pointed or undercut teeth). Each raises ScenarioError (exit 2)."""

from __future__ import annotations

from meshgen.geometry import GearGeometry
from wormsim.scenario import Scenario


def validate_geometry(scenario: Scenario) -> GearGeometry | None:
    """Derive the gear geometry and check worm and wheel teeth (meshgen.geometry.derive, meshgen.worm.check_worm,
    meshgen.wheel.check_wheel); returns the GearGeometry, or None where no gear is used (no gear: block, or model
    wedge with its own wedge: block). The wedge derived from gear: takes the gear's lead angle, radii and inertias,
    so a gear that cannot be made is refused there too."""
    if scenario.gear is None or (scenario.model == "wedge" and scenario.wedge is not None):
        return None
    from meshgen import wheel, worm
    from wormsim.physics.geometry import derive, geometry_errors

    g = derive(scenario.gear)
    with geometry_errors():
        worm.check_worm(g, wheel.hob_radius(g))
        wheel.check_wheel(g)
    return g
