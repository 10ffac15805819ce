"""The simulator's edge to meshgen: gear geometry and collision pieces for a scenario, with meshgen's GeometryError
turned into ScenarioError (exit 2; the message already names the `gear:` field)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from meshgen import displaced as _displaced
from meshgen import geometry as _geometry
from meshgen import kinematic_tca as _kinematic_tca
from meshgen.displaced import Deviations, ErrorsData
from meshgen.geometry import GearData, GearGeometry, GeometryError
from meshgen.kinematic_tca import KinematicTCA
from wormsim.scenario import Scenario, ScenarioError, unit_hint

if TYPE_CHECKING:  # meshgen.pieces (trimesh, scipy.spatial: ~1 s) is imported only where pieces are built
    from meshgen.pieces import GearSet


@contextmanager
def geometry_errors() -> Iterator[None]:
    """meshgen's GeometryError as ScenarioError (invalid input)."""
    try:
        yield
    except GeometryError as exc:
        msg = str(exc)
        m = re.match(r"gear\.(\w+_mm) = ([-+0-9.eE]+)", msg)
        raise ScenarioError(msg + (unit_hint(m.group(1), float(m.group(2))) if m else "")) from None


def derive(gear: GearData) -> GearGeometry:
    """meshgen.geometry.derive, raising ScenarioError on impossible gear data."""
    with geometry_errors():
        return _geometry.derive(gear)


def gear_set(scenario: Scenario, resolution: str | None = None) -> tuple[GearGeometry, GearSet]:
    """(geometry, collision pieces) of the scenario's gear at `resolution` (default: simulation.resolution)."""
    if scenario.gear is None:
        raise ScenarioError("gear: this needs a gear: block (model contact3d or torsional)")
    from meshgen import pieces as _pieces

    geo = derive(scenario.gear)
    with geometry_errors():
        return geo, _pieces.build_gear_set(geo, resolution=resolution or scenario.simulation.resolution)


def solid_set(scenario: Scenario, resolution: str | None = None) -> tuple[GearGeometry, GearSet]:
    """(geometry, the solid meshes without collision pieces: meshgen.pieces.build_solids) of the scenario's gear."""
    if scenario.gear is None:
        raise ScenarioError("gear: this needs a gear: block (model contact3d or torsional)")
    from meshgen import pieces as _pieces

    geo = derive(scenario.gear)
    with geometry_errors():
        return geo, _pieces.build_solids(geo, resolution=resolution or scenario.simulation.resolution)


def displaced_pair(errors: ErrorsData, geo: GearGeometry) -> tuple[Deviations, KinematicTCA] | None:
    """The errors: block as meshgen.displaced's Deviations, checked against its limits, and the kinematic TCA of the
    displaced flanks (meshgen.kinematic_tca, with its play check); None without errors (the perfect pair's path).
    Errors beyond a limit, or flanks that leave no play, raise ScenarioError (exit 2)."""
    dev = _displaced.Deviations.from_data(errors)
    if dev.is_zero():
        return None
    with geometry_errors():
        dev = _displaced.check_limits(geo, errors)
        return dev, _kinematic_tca.check_play(geo, _kinematic_tca.kinematic_tca(geo, dev))
