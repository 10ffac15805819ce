"""The pieces' geom -> window slot lookup (wormsim.contact3d.sources.slot_lookup) is keyed by the model's content, not
by the Python object: two models in one process (a sweep's worker) each get their own table, also when the second
lives at the first one's address."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tests.conftest import SCENARIOS
from wormsim.contact3d.mjcf import build_model
from wormsim.contact3d.sources import slot_lookup as _slot_lookup
from wormsim.scenario import load_scenario


def _model(ngeom: int, slots: list[list[int]]) -> SimpleNamespace:
    return SimpleNamespace(model=SimpleNamespace(ngeom=ngeom), wheel_slot_geoms=np.array(slots, dtype=int))


def _expected(ngeom: int, slots: list[list[int]]) -> np.ndarray:
    lut = np.full(ngeom, -1)
    for s, row in enumerate(slots):
        lut[row] = s
    return lut


def test_two_models_in_one_process_get_their_own_tables():
    a_slots, b_slots = [[2, 3], [4, 5], [6, 7]], [[1, 2, 3], [4, 5, 6]]
    bm = _model(8, a_slots)
    np.testing.assert_array_equal(_slot_lookup(bm), _expected(8, a_slots))
    # the same object (the same id()) now holding another model: an id()-keyed cache returned the first table
    bm.model.ngeom, bm.wheel_slot_geoms = 9, np.array(b_slots, dtype=int)
    np.testing.assert_array_equal(_slot_lookup(bm), _expected(9, b_slots))
    # and the first model again, from a new object
    np.testing.assert_array_equal(_slot_lookup(_model(8, a_slots)), _expected(8, a_slots))


def test_two_piece_models_built_in_one_process_read_their_own_slots():
    """Two different gears' models (screw jack and seat motor demo, coarse pieces) in one process, the first again
    after the second: each lookup maps exactly its own slot geoms to their slots."""
    pieces = ["contact.geometry=pieces", "simulation.resolution=coarse"]
    jack = build_model(load_scenario(SCENARIOS / "screw_jack.yaml", pieces))
    seat = build_model(load_scenario(SCENARIOS / "seat_motor_demo.yaml", pieces))
    assert jack.wheel_slot_geoms.shape != seat.wheel_slot_geoms.shape
    for bm in (jack, seat, jack):
        lut = _slot_lookup(bm)
        assert len(lut) == bm.model.ngeom
        assert (lut >= 0).sum() == bm.wheel_slot_geoms.size
        assert all(lut[g] == s for s, row in enumerate(bm.wheel_slot_geoms) for g in row)
